"""The content of a STEP or IGES file checked before OpenCascade sees it.

OCCT's readers trust what they parse: a dangling ``#`` reference or an IGES
directory pointer past the end of the file can crash them, a NaN, an infinity or
a coordinate of 1e308 can make them spin. :func:`content_problems` finds those in
the text (a few regular-expression passes, about 0.1 s per MB) and says where,
so :func:`surfprep.read` refuses the file with a message naming the entity
instead of leaving it to the reader (which runs isolated anyway,
:mod:`.isolation`).

* STEP (ISO 10303-21): every ``#n`` referenced in the DATA section is defined
  there; every real number is finite and at most :data:`MAX_MAGNITUDE` in size;
  no bare ``NaN``/``INF`` token stands where a parameter does.
* IGES: every directory entry's parameter-data pointer and line count lie
  inside the parameter section; its real numbers (``E`` or ``D`` exponents) are
  finite and at most :data:`MAX_MAGNITUDE`; no ``NaN``/``INF`` token.
"""

from __future__ import annotations

import math
import re

__all__ = ["MAX_MAGNITUDE", "content_problems"]

#: a real number larger than this in magnitude is refused (no CAD model comes near:
#: 1e100 mm is 1e79 light years)
MAX_MAGNITUDE = 1e100
#: at most this many problems are listed in a message
MAX_LISTED = 3
NEWLINE = b"\n"

_STEP_STRING = re.compile(rb"'(?:[^']|'')*'")
_STEP_DEFINED = re.compile(rb"#(\d+)\s*=")
_STEP_REFERENCE = re.compile(rb"#(\d+)")
_STEP_ENTITY = re.compile(rb"#(\d+)\s*=\s*([A-Za-z_0-9]*)")
#: a positive exponent of 100 or more after a digit or a point, or a hundred-digit run: the
#: only numbers that can exceed MAX_MAGNITUDE (found first, then read whole)
_LARGE_EXPONENT = re.compile(rb"[\d.][EeDd]\+?0*[1-9]\d{2,}|\d{100,}")
_NUMBER_ENDING = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?$")
_NOT_FINITE_TOKEN = re.compile(rb"[(,]\s*[-+]?(?:nan|inf(?:inity)?)\s*(?=[,);])", re.I)


def content_problems(data: bytes, file_format: str) -> list[str]:
    """Problems found in a file's bytes (``file_format`` "STEP" or "IGES"), at most
    :data:`MAX_LISTED` of each kind; empty when none."""
    return _step_problems(data) if file_format == "STEP" else _iges_problems(data)


def _too_large(token: bytes) -> bool:
    try:
        value = float(token.replace(b"D", b"E").replace(b"d", b"e"))
    except ValueError:
        return False
    return not math.isfinite(value) or abs(value) > MAX_MAGNITUDE


# ---------------------------------------------------------------------- STEP
def _step_problems(data: bytes) -> list[str]:
    start = data.find(b"DATA;")
    end = data.rfind(b"ENDSEC;")
    body = data[start + 5:end] if start >= 0 and end > start else data
    body = _STEP_STRING.sub(b"''", body)
    problems = []
    defined = {int(n) for n in _STEP_DEFINED.findall(body)}
    dangling = []
    for statement in body.split(b";"):
        head = _STEP_ENTITY.search(statement)
        if head is None:
            continue
        refs = {int(n) for n in _STEP_REFERENCE.findall(statement[head.end():])}
        for ref in sorted(refs - defined):
            dangling.append(f"#{int(head.group(1))} ({head.group(2).decode(errors='replace')}) "
                            f"refers to #{ref}, which is not defined")
            if len(dangling) >= MAX_LISTED:
                break
        if len(dangling) >= MAX_LISTED:
            break
    problems += dangling
    problems += _number_problems(body, _step_entity_at)
    return problems


def _step_entity_at(body: bytes, position: int) -> str:
    start = body.rfind(b"#", 0, body.rfind(b"=", 0, position) + 1)
    head = _STEP_ENTITY.match(body, start) if start >= 0 else None
    return f"#{int(head.group(1))} ({head.group(2).decode(errors='replace')})" if head \
        else f"byte {position}"


def _number_problems(body: bytes, where) -> list[str]:
    out = []
    for match in _NOT_FINITE_TOKEN.finditer(body):
        out.append(f"{where(body, match.start())} holds {match.group().strip(b'(, ').decode()}")
        if len(out) >= MAX_LISTED:
            return out
    for match in _LARGE_EXPONENT.finditer(body):
        head = body[max(0, match.start() - 64):match.end()]
        whole = _NUMBER_ENDING.search(head)
        token = whole.group() if whole else match.group()
        if _too_large(token):
            out.append(f"{where(body, match.start())} holds the number "
                       f"{token.decode()} (not finite or beyond {MAX_MAGNITUDE:g})")
            if len(out) >= MAX_LISTED:
                return out
    return out


# ---------------------------------------------------------------------- IGES
def _iges_problems(data: bytes) -> list[str]:
    lines = [line.rstrip(b"\r") for line in data.split(b"\n") if line.strip()]
    directory = [ln for ln in lines if len(ln) >= 73 and ln[72:73] == b"D"]
    parameters = [ln for ln in lines if len(ln) >= 73 and ln[72:73] == b"P"]
    problems = []
    n_params = len(parameters)
    for k in range(0, len(directory) - 1, 2):
        first, second = directory[k], directory[k + 1]
        kind, pointer = _field(first, 0), _field(first, 1)
        count = _field(second, 3)
        if kind is None or pointer is None:
            continue
        if pointer < 1 or pointer > n_params or (count is not None
                                                 and pointer + max(count, 1) - 1 > n_params):
            problems.append(f"directory entry {k + 1} (type {kind}) points to parameter lines "
                            f"{pointer}..{pointer + max(count or 1, 1) - 1}, the file has "
                            f"{n_params}")
            if len(problems) >= MAX_LISTED:
                break
    body = b"\n".join(ln[:64] for ln in parameters)
    problems += _number_problems(body, _iges_line_at)
    return problems


def _iges_line_at(body: bytes, position: int) -> str:
    return f"parameter line {body.count(NEWLINE, 0, position) + 1}"


def _field(line: bytes, index: int) -> int | None:
    text = line[8 * index:8 * index + 8].strip()
    try:
        return int(text) if text else None
    except ValueError:
        return None
