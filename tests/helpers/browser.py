"""Headless Chromium for the tests of the HTML report, driven through the DevTools protocol
over a pipe (``--remote-debugging-pipe``: JSON messages ending in a NUL byte on file
descriptors 3 and 4 of the browser; standard library only, no network port).

:func:`chromium_path` finds the browser or skips the test with the install command (CI
installs it: ``apt-get install -y chromium``). :func:`open_page` opens a local HTML file in
a fresh browser and gives a :class:`Page`: JavaScript values read back, PNG screenshots of
elements as the browser composited them, real mouse input (drag, wheel, click), and the
console messages, exceptions and requests the page made.
"""

from __future__ import annotations

import base64
import fcntl
import json
import os
import selectors
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Self

import pytest

#: where Debian puts it, then the names on PATH
CANDIDATES = ("/usr/bin/chromium", "chromium", "chromium-browser")

#: headless, no sandbox (root in a container), no GPU, and none of the background
#: connections a closed network refuses
BASE_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-dev-shm-usage",
    "--hide-scrollbars",
    "--mute-audio",
)
#: WebGL through SwiftShader (software) without a GPU; Chromium >= 137 wants the opt-in
WEBGL_FLAGS = ("--use-angle=swiftshader", "--enable-unsafe-swiftshader")
#: no WebGL at all (the page's fallback)
NO_WEBGL_FLAGS = ("--disable-webgl", "--disable-3d-apis")

#: puts the pipe ends given as argv[1], argv[2] on descriptors 3 and 4, execs argv[3:]
_LAUNCHER = ("import os, sys; r, w = int(sys.argv[1]), int(sys.argv[2]); os.dup2(r, 3); "
             "os.dup2(w, 4); os.close(r); os.close(w); os.execv(sys.argv[3], sys.argv[3:])")


def chromium_path() -> str:
    """The Chromium executable, or skip the calling test saying how to install it."""
    for name in CANDIDATES:
        found = shutil.which(name)
        if found:
            return found
    pytest.skip("Chromium is not installed: apt-get install chromium")


class DevTools:
    """A Chromium process and its DevTools pipe.

    Parameters
    ----------
    flags : sequence of str
        Flags added to :data:`BASE_FLAGS`.
    timeout : float
        Seconds any one wait may take before ``TimeoutError``.
    """

    def __init__(self, flags=(), *, timeout: float = 20.0, window=(1200, 900)) -> None:
        self.timeout = timeout
        self.events: list[dict] = []
        self._next_id = 0
        self._buffer = b""
        self._profile = tempfile.TemporaryDirectory(prefix="surfprep-chromium-")
        to_browser_r, to_browser_w = os.pipe()
        from_browser_r, from_browser_w = os.pipe()
        # the browser's ends moved to >= 10, so that putting them on 3 and 4 cannot clobber
        # one another; a small Python launcher does that and execs the browser
        high_r = fcntl.fcntl(to_browser_r, fcntl.F_DUPFD_CLOEXEC, 10)
        high_w = fcntl.fcntl(from_browser_w, fcntl.F_DUPFD_CLOEXEC, 10)
        os.close(to_browser_r)
        os.close(from_browser_w)
        command = [sys.executable, "-c", _LAUNCHER, str(high_r), str(high_w),
                   chromium_path(), *BASE_FLAGS, *flags, f"--user-data-dir={self._profile.name}",
                   f"--window-size={window[0]},{window[1]}", "--remote-debugging-pipe",
                   "about:blank"]
        try:
            self.process = subprocess.Popen(command, stdin=subprocess.DEVNULL,
                                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                            pass_fds=(high_r, high_w))
        finally:
            os.close(high_r)
            os.close(high_w)
        self._write = to_browser_w
        self._read = from_browser_r
        self._selector = selectors.DefaultSelector()
        self._selector.register(self._read, selectors.EVENT_READ)

    # ---------------------------------------------------------------- protocol
    def _receive(self, deadline: float) -> dict:
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not self._selector.select(left):
                raise TimeoutError("Chromium did not answer in time")
            chunk = os.read(self._read, 1 << 20)
            if not chunk:
                raise ConnectionError("Chromium closed its DevTools pipe")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method: str, params: dict | None = None, session: str | None = None) -> dict:
        """Send one command and return its result (events met meanwhile go to ``events``)."""
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self._write, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + self.timeout
        while True:
            reply = self._receive(deadline)
            if reply.get("id") == self._next_id:
                if "error" in reply:
                    raise RuntimeError(f"DevTools {method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_event(self, method: str, deadline: float) -> dict:
        """The first event ``method`` seen (already received or arriving before ``deadline``)."""
        for event in self.events:
            if event.get("method") == method:
                return event
        while True:
            event = self._receive(deadline)
            self.events.append(event)
            if event.get("method") == method:
                return event

    def close(self) -> None:
        try:
            if self.process.poll() is None:
                try:
                    self.call("Browser.close")
                except (OSError, TimeoutError, ConnectionError, RuntimeError):
                    pass
            try:
                self.process.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(timeout=5)
        finally:
            self._selector.close()
            os.close(self._write)
            os.close(self._read)
            self._profile.cleanup()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _console(events: list[dict]) -> list[tuple[str, str]]:
    out = []
    for event in events:
        method, params = event.get("method"), event.get("params", {})
        if method == "Runtime.consoleAPICalled":
            level = "error" if params["type"] in ("error", "assert") else params["type"]
            text = " ".join(str(a.get("value", a.get("description", ""))) for a in params["args"])
            out.append((level, text))
        elif method == "Runtime.exceptionThrown":
            details = params["exceptionDetails"]
            out.append(("error", details.get("exception", {}).get("description", details["text"])))
        elif method == "Log.entryAdded":
            entry = params["entry"]
            out.append((entry["level"], f"{entry.get('source')}: {entry['text']}"))
    return out


class Page:
    """One page open in a :class:`DevTools` browser: JavaScript, screenshots, real mouse input.

    Console messages, exceptions and requests are gathered from the DevTools events as they
    arrive (:attr:`console`, :attr:`errors`, :attr:`requests`).
    """

    def __init__(self, browser: DevTools, session: str) -> None:
        self.browser = browser
        self.session = session

    def call(self, method: str, params: dict | None = None) -> dict:
        return self.browser.call(method, params, session=self.session)

    def js(self, expression: str):
        """The value of a JavaScript expression (promises awaited), made JSON and back."""
        result = self.call("Runtime.evaluate", {"expression": f"JSON.stringify({expression})",
                                                "returnByValue": True, "awaitPromise": True})
        if "exceptionDetails" in result:
            raise RuntimeError(f"evaluating {expression!r}: {result['exceptionDetails']}")
        value = result["result"].get("value")
        return None if value is None else json.loads(value)

    def wait_rendered(self, timeout: float = 10.0) -> str:
        """``document.body.dataset.rendered`` once it is no longer ``"pending"`` (or the
        timeout has passed)."""
        deadline = time.monotonic() + timeout
        rendered = self.js("document.body.dataset.rendered")
        while rendered == "pending" and time.monotonic() < deadline:
            time.sleep(0.05)
            rendered = self.js("document.body.dataset.rendered")
        return rendered

    def settle(self, milliseconds: int = 150) -> None:
        """Wait for two animation frames and ``milliseconds`` (redraws requested by input)."""
        self.js("new Promise(function (done) { requestAnimationFrame(function () { "
                f"requestAnimationFrame(function () {{ setTimeout(done, {milliseconds}); }}); }}); }})")

    def box(self, selector: str) -> dict:
        """The element's box in CSS pixels: ``x, y, width, height``."""
        return self.js(f"(function (r) {{ return {{x: r.x, y: r.y, width: r.width, height: r.height}}; }})"
                       f"(document.querySelector({json.dumps(selector)}).getBoundingClientRect())")

    def screenshot(self, selector: str) -> bytes:
        """PNG of the element ``selector`` as the browser composited it."""
        box = self.box(selector)
        clip = {**box, "scale": 1}
        data = self.call("Page.captureScreenshot", {"format": "png", "clip": clip,
                                                    "captureBeyondViewport": True})["data"]
        return base64.b64decode(data)

    def _mouse(self, kind: str, x: float, y: float, **extra) -> None:
        self.call("Input.dispatchMouseEvent", {"type": kind, "x": x, "y": y, **extra})

    def drag(self, start: tuple[float, float], end: tuple[float, float], *, button: str = "left",
             shift: bool = False, steps: int = 8) -> None:
        """Press ``button`` at ``start``, move to ``end`` in ``steps``, release."""
        modifiers = 8 if shift else 0
        buttons = {"left": 1, "right": 2, "middle": 4}[button]
        self._mouse("mouseMoved", *start, modifiers=modifiers)
        self._mouse("mousePressed", *start, button=button, buttons=buttons, clickCount=1,
                    modifiers=modifiers)
        for k in range(1, steps + 1):
            x = start[0] + (end[0] - start[0]) * k / steps
            y = start[1] + (end[1] - start[1]) * k / steps
            self._mouse("mouseMoved", x, y, button=button, buttons=buttons, modifiers=modifiers)
        self._mouse("mouseReleased", *end, button=button, buttons=0, clickCount=1,
                    modifiers=modifiers)

    def wheel(self, at: tuple[float, float], delta_y: float) -> None:
        """One wheel turn of ``delta_y`` pixels at ``at`` (positive: away, zooming out)."""
        self._mouse("mouseWheel", *at, deltaX=0, deltaY=delta_y)

    def click(self, selector: str) -> None:
        """A real left click at the centre of the element ``selector``."""
        box = self.box(selector)
        at = (box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
        self._mouse("mouseMoved", *at)
        self._mouse("mousePressed", *at, button="left", buttons=1, clickCount=1)
        self._mouse("mouseReleased", *at, button="left", buttons=0, clickCount=1)

    @property
    def console(self) -> list[tuple[str, str]]:
        """Every console message and uncaught exception so far as ``(level, text)``; levels
        are the DevTools ones (``"error"``, ``"warning"``, ``"log"``...)."""
        return _console(self.browser.events)

    @property
    def errors(self) -> list[str]:
        """The texts of the console errors and uncaught exceptions so far."""
        return [text for level, text in self.console if level == "error"]

    @property
    def requests(self) -> list[str]:
        """The URL of every request the page made so far."""
        return [e["params"]["request"]["url"] for e in self.browser.events
                if e.get("method") == "Network.requestWillBeSent"]


@contextmanager
def open_page(path: Path, *, webgl: bool = True, timeout: float = 20.0) -> Iterator[Page]:
    """Open the local file ``path`` in a fresh headless Chromium and yield the :class:`Page`
    once its load event has fired.

    Parameters
    ----------
    path : Path
        An HTML file.
    webgl : bool
        True: WebGL through SwiftShader (:data:`WEBGL_FLAGS`); False: WebGL switched off
        (:data:`NO_WEBGL_FLAGS`).
    timeout : float
        Seconds any one DevTools exchange, and the load, may take.
    """
    with DevTools(WEBGL_FLAGS if webgl else NO_WEBGL_FLAGS, timeout=timeout) as browser:
        target = browser.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = browser.call("Target.attachToTarget",
                               {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Runtime", "Log", "Network", "Page"):
            browser.call(f"{domain}.enable", session=session)
        browser.events.clear()
        browser.call("Page.navigate", {"url": path.resolve().as_uri()}, session=session)
        browser.wait_event("Page.loadEventFired", time.monotonic() + timeout)
        yield Page(browser, session)
