"""A seeded corpus of corrupt STEP and IGES files, made from the bundled samples.

What a careless user and a fuzzer feed a CAD reader: bytes flipped, a chunk cut
out with the trailer kept, ``#`` references that dangle or point at an entity of
the wrong kind or at themselves, NaN / INF / 1e308 / 1e200 coordinates,
decreasing knots, degrees of 0, -1 or 99, zero and negative weights, a pole row
or a single pole dropped from a net (ragged), IGES directory pointers past the
end, bytes that are not UTF-8. :func:`corpus` makes the same files for the same
seed; nothing is stored in the repository.

:func:`run_info` runs one file through ``surfprep info FILE --json -`` as a user's
process would (a forked child: a crash or a hang of anything after the reader
shows too) and sorts the outcome. ``python tests/helpers/mutations.py`` prints the
outcome table of the whole corpus; ``python tests/helpers/mutations.py --write
OUTDIR`` writes the corpus to a folder.
"""

from __future__ import annotations

import random
import re
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

SAMPLES = Path(__file__).resolve().parents[2] / "step_samples"
#: the samples mutated (small, STEP and IGES, plain and rational, one trimmed face)
SOURCES = ("occt_fuselage.stp", "synthetic_named_faces.step",
           "overture_marscapsule_proe.igs", "occt_catia4_face_L1.igs")
#: variants of every mutation kind per source
VARIANTS = 30
SEED = 20261205


@dataclass(frozen=True)
class Mutant:
    """One corrupt file: its name (source, kind, variant), bytes and source's face count."""

    name: str
    kind: str
    source: str
    data: bytes


# ----------------------------------------------------------------- helpers
_STEP_REF = re.compile(rb"#(\d+)")
_STEP_POINT = re.compile(rb"CARTESIAN_POINT\s*\(\s*'[^']*'\s*,\s*\(([^)]*)\)")
_STEP_BSPLINE = re.compile(rb"B_SPLINE_(?:SURFACE|CURVE)_WITH_KNOTS\s*\(")
_STEP_SURFACE_NET = re.compile(rb"B_SPLINE_SURFACE_WITH_KNOTS\s*\(\s*'[^']*'\s*,\s*\d+\s*,\s*\d+\s*,\s*\(")
_BAD_NUMBERS = (b"NaN", b"INF", b"-INF", b"1.E+308", b"-1.E+308", b"1.E+200", b"1.7976931348623157E+308")


def _data_start(data: bytes) -> int:
    i = data.find(b"DATA;")
    return i + 5 if i >= 0 else 0


def _flip_bytes(data: bytes, rng: random.Random, lo: int, hi: int) -> bytes:
    out = bytearray(data)
    for _ in range(rng.randint(1, 6)):
        k = rng.randrange(lo, hi)
        out[k] = rng.choice(b"#(),;.'0123456789-+EeAZaz ")
    return bytes(out)


def _cut_chunk(data: bytes, rng: random.Random, lo: int, hi: int) -> bytes:
    a = rng.randrange(lo, hi)
    b = min(hi, a + rng.randint(1, max(2, (hi - lo) // 8)))
    return data[:a] + data[b:]


def _non_utf8(data: bytes, rng: random.Random, lo: int, hi: int) -> bytes:
    k = rng.randrange(lo, hi)
    return data[:k] + rng.choice([b"\xff\xfe", b"\xc3\x28", b"\x80\x80\x80", b"\xe9"]) + data[k:]


def _replace_span(data: bytes, start: int, end: int, new: bytes) -> bytes:
    return data[:start] + new + data[end:]


# -------------------------------------------------------------------- STEP
def _step_mutants(name: str, data: bytes, rng: random.Random) -> Iterator[tuple[str, bytes]]:
    lo = _data_start(data)
    hi = data.rfind(b"ENDSEC;")
    refs = [m for m in _STEP_REF.finditer(data, lo, hi) if data[m.end():m.end() + 1] != b"="
            and not data[m.end():m.end() + 3].lstrip().startswith(b"=")]
    points = list(_STEP_POINT.finditer(data, lo, hi))
    knots = [m for m in re.finditer(rb"\(([-+0-9.E, ]+)\),\s*\.(?:UNSPECIFIED|PIECEWISE_BEZIER_KNOTS|"
                                    rb"QUASI_UNIFORM_KNOTS|UNIFORM_KNOTS)\.", data)]
    splines = list(_STEP_BSPLINE.finditer(data, lo, hi))
    nets = list(_STEP_SURFACE_NET.finditer(data, lo, hi))
    for v in range(VARIANTS):
        yield "byte_flips", _flip_bytes(data, rng, lo, hi)
        yield "chunk_cut", _cut_chunk(data, rng, lo, hi)
        yield "non_utf8", _non_utf8(data, rng, lo, hi)
        m = rng.choice(refs)
        target = rng.choice([b"#999999", b"#0", b"#" + str(rng.randint(1, 40)).encode()])
        yield "dangling_or_wrong_ref", _replace_span(data, m.start(), m.end(), target)
        m = rng.choice(refs)
        head = data.rfind(b"#", lo, data.rfind(b"=", lo, m.start()))
        own = _STEP_REF.match(data, head)
        if own is not None:
            yield "self_reference", _replace_span(data, m.start(), m.end(), own.group())
        p = rng.choice(points)
        coords = p.group(1).split(b",")
        coords[rng.randrange(len(coords))] = rng.choice(_BAD_NUMBERS)
        yield "bad_coordinate", _replace_span(data, p.start(1), p.end(1), b",".join(coords))
        if knots:
            k = rng.choice(knots)
            values = k.group(1).split(b",")
            if len(values) >= 2:
                i = rng.randrange(len(values) - 1)
                values[i], values[i + 1] = values[i + 1], values[i]
                if values[i] == values[i + 1]:
                    values[i] = b"9.5"
                yield "decreasing_knots", _replace_span(data, k.start(1), k.end(1), b",".join(values))
        if splines:
            s = rng.choice(splines)
            deg = re.compile(rb"'[^']*'\s*,\s*(\d+)").match(data, s.end())
            if deg is not None:
                yield "bad_degree", _replace_span(data, deg.start(1), deg.end(1),
                                                  rng.choice([b"0", b"-1", b"99", b"2"]))
        if nets:
            n = rng.choice(nets)
            depth, k, rows = 1, n.end(), []
            row_start = None
            while depth and k < len(data):
                c = data[k:k + 1]
                if c == b"(":
                    depth += 1
                    if depth == 2:
                        row_start = k
                elif c == b")":
                    depth -= 1
                    if depth == 1 and row_start is not None:
                        rows.append((row_start, k + 1))
                k += 1
            if len(rows) >= 2:
                a, b = rows[rng.randrange(len(rows))]
                end = b + 1 if data[b:b + 1] == b"," else b
                yield "dropped_pole_row", data[:a] + data[end:]
                row = data[a:b]
                cut = row.rfind(b",")
                if cut > 0:
                    yield "ragged_net", data[:a] + row[:cut] + b")" + data[b:]


# -------------------------------------------------------------------- IGES
def _iges_sections(data: bytes) -> tuple[list[bytes], str]:
    newline = "\r\n" if b"\r\n" in data[:200] else "\n"
    return data.split(newline.encode()), newline


def _iges_mutants(name: str, data: bytes, rng: random.Random) -> Iterator[tuple[str, bytes]]:
    lines, newline = _iges_sections(data)
    nl = newline.encode()
    p_lines = [i for i, ln in enumerate(lines) if len(ln) >= 73 and ln[72:73] == b"P"]
    d_lines = [i for i, ln in enumerate(lines) if len(ln) >= 73 and ln[72:73] == b"D"]
    d_first = d_lines[0::2]
    p_lo = sum(len(ln) + len(nl) for ln in lines[:p_lines[0]])
    p_hi = sum(len(ln) + len(nl) for ln in lines[:p_lines[-1] + 1])
    de_by_type: dict[int, list[int]] = {}
    for i in d_first:
        try:
            de_by_type.setdefault(int(lines[i][:8]), []).append(i)
        except ValueError:
            pass

    def with_line(index: int, new: bytes) -> bytes:
        out = list(lines)
        out[index] = new
        return nl.join(out)

    def entity_lines(de_index: int) -> list[int]:
        pointer = int(lines[de_index][8:16])
        count = int(lines[de_index + 1][24:32] or b"1")
        return [p_lines[k] for k in range(pointer - 1, min(pointer - 1 + count, len(p_lines)))]

    def replace_token(de_index: int, pick: Callable[[list[bytes]], int], new: bytes
                      ) -> bytes | None:
        """Replace one parameter of an entity when the line has room for it."""
        for index in entity_lines(de_index):
            text = lines[index][:64]
            tokens = re.split(rb"([,;])", text.rstrip())
            values = [k for k in range(0, len(tokens), 2) if tokens[k].strip()]
            if not values:
                continue
            k = values[pick(values) % len(values)]
            tokens[k] = new
            joined = b"".join(tokens)
            if len(joined) <= 64:
                return with_line(index, joined.ljust(64) + lines[index][64:])
        return None

    surfaces = de_by_type.get(128, [])
    for v in range(VARIANTS):
        yield "byte_flips", _flip_bytes(data, rng, p_lo, p_hi)
        yield "chunk_cut", _cut_chunk(data, rng, p_lo, p_hi)
        yield "non_utf8", _non_utf8(data, rng, p_lo, p_hi)
        d = rng.choice(d_first)
        line = lines[d]
        yield "pointer_past_end", with_line(d, line[:8] + rng.choice([b"   99999", b"      -1",
                                                                      b"       0"]) + line[16:])
        if surfaces:
            s = rng.choice(surfaces)
            degree = replace_token(s, lambda idx: rng.choice([3, 4]),
                                   rng.choice([b"-1", b"0", b"99"]))
            if degree is not None:
                yield "bad_degree", degree
            bad = replace_token(s, lambda idx: rng.randrange(len(idx) // 2, len(idx)),
                                rng.choice(_BAD_NUMBERS).replace(b"E", b"D"))
            if bad is not None:
                yield "bad_coordinate", bad
            weight = replace_token(s, lambda idx: rng.randrange(12, max(13, len(idx) // 3)),
                                   rng.choice([b"0.", b"-1.", b"-0.5"]))
            if weight is not None:
                yield "bad_weight", weight
            knot = replace_token(s, lambda idx: rng.randrange(10, 14), b"9.5")
            if knot is not None:
                yield "decreasing_knots", knot


# ------------------------------------------------------------------ corpus
def corpus(seed: int = SEED) -> list[Mutant]:
    """Every mutant of every source, the same for the same seed (a thousand and more)."""
    out = []
    for source in SOURCES:
        data = (SAMPLES / source).read_bytes()
        rng = random.Random(f"{seed}:{source}")
        make = _step_mutants if source.lower().endswith((".stp", ".step")) else _iges_mutants
        counts: dict[str, int] = {}
        for kind, mutated in make(source, data, rng):
            if mutated == data:
                continue
            counts[kind] = counts.get(kind, 0) + 1
            stem, suffix = source.rsplit(".", 1)
            out.append(Mutant(f"{stem}__{kind}_{counts[kind]:02d}.{suffix}", kind, source,
                              mutated))
    return out


# ----------------------------------------------------------------- running
#: seconds one ``surfprep info`` run may take before it counts as a hang
RUN_TIMEOUT = 60.0


@dataclass(frozen=True)
class Outcome:
    """How ``surfprep info FILE --json -`` ended on one mutant.

    ``kind``: "ok" (exit 0, a report), "skipped" (exit 1: done, entities left out
    and said), "error" (exit 2, one ``surfprep: error:`` line), or a failure:
    "crash" (a signal), "hang", "internal error", "traceback", "bad output",
    "silent loss" (exit 0 with fewer faces than the unmutated file and no word).
    """

    kind: str
    code: int | None
    faces: int | None
    dropped: int
    stderr: str

    @property
    def failed(self) -> bool:
        return self.kind not in ("ok", "skipped", "error")


def _info(path: str) -> tuple[int, str, str]:
    """``surfprep info PATH --json -`` in this process, its output captured."""
    import contextlib
    import io

    from surfprep.plugin import cli
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli.main(["info", path, "--json", "-"])
    return code, out.getvalue(), err.getvalue()


def warm_up() -> None:
    """Import the command line and load the compiled kernels ``info`` uses, here, once:
    every forked run inherits them instead of loading them again."""
    import surfprep.plugin.cli  # noqa: F401
    _info(str(SAMPLES / SOURCES[0]))


def run_info(mutant: Mutant, folder: Path, timeout: float = RUN_TIMEOUT,
             source_faces: int | None = None) -> Outcome:
    """Write ``mutant`` into ``folder`` and run ``surfprep info`` on it in a forked child
    (call :func:`warm_up` first); ``source_faces`` is what the unmutated file holds."""
    import json

    from surfprep.plugin.isolation import ChildCrashed, ChildTimedOut, call_isolated
    path = folder / mutant.name
    path.write_bytes(mutant.data)
    try:
        code, out, err = call_isolated(_info, str(path), timeout=timeout)
    except ChildCrashed as exc:
        return Outcome("crash", None, None, 0, str(exc))
    except ChildTimedOut as exc:
        return Outcome("hang", None, None, 0, str(exc))
    lines = [ln for ln in err.splitlines() if ln.strip()]
    if "Traceback" in err or any(not ln.startswith("surfprep:") for ln in lines):
        return Outcome("traceback", code, None, 0, err)
    if "internal error" in err:
        return Outcome("internal error", code, None, 0, err)
    if code == 2:
        ok = len(lines) == 1 and lines[0].startswith("surfprep: error: ")
        return Outcome("error" if ok else "bad output", code, None, 0, err)
    try:
        report = json.loads(out)
    except ValueError:
        return Outcome("bad output", code, None, 0, err)
    dropped, faces = len(report.get("dropped", [])), report.get("n_faces")
    kind = "ok" if code == 0 and not dropped else ("skipped" if code == 1 and dropped else
                                                   "bad output")
    if kind == "ok" and source_faces is not None and faces is not None and faces < source_faces:
        kind = "silent loss"
    return Outcome(kind, code, faces, dropped, err)


def source_faces(source: str) -> int:
    """Faces OpenCascade reads from the unmutated source."""
    import surfprep
    return surfprep.read(SAMPLES / source).n_faces


def outcome_table(outcomes: dict[str, Outcome], mutants: list[Mutant]) -> str:
    """Markdown: runs per outcome, and per kind of mutation."""
    from collections import Counter
    by_outcome = Counter(o.kind for o in outcomes.values())
    kinds = sorted({m.kind for m in mutants})
    lines = ["| outcome | runs |", "|---|---|"]
    lines += [f"| {k} | {by_outcome[k]} |" for k in ("ok", "skipped", "error") if by_outcome[k]]
    lines += [f"| **{k}** | {n} |" for k, n in by_outcome.items()
              if k not in ("ok", "skipped", "error")]
    lines += ["", "| mutation | files | exit 0 | exit 1 (entities left out, said) | "
              "exit 2 (one error line) | failures |", "|---|---|---|---|---|---|"]
    for kind in kinds:
        runs = [outcomes[m.name] for m in mutants if m.kind == kind]
        count = Counter(o.kind for o in runs)
        failures = sum(o.failed for o in runs)
        lines.append(f"| {kind} | {len(runs)} | {count['ok']} | {count['skipped']} | "
                     f"{count['error']} | {failures} |")
    return "\n".join(lines)


if __name__ == "__main__":
    import tempfile
    mutants = corpus()
    if len(sys.argv) > 2 and sys.argv[1] == "--write":
        folder = Path(sys.argv[2])
        folder.mkdir(parents=True, exist_ok=True)
        for m in mutants:
            (folder / m.name).write_bytes(m.data)
        print(f"{len(mutants)} files written to {folder}")
        raise SystemExit(0)
    warm_up()
    faces = {source: source_faces(source) for source in SOURCES}
    with tempfile.TemporaryDirectory() as tmp:
        results = {m.name: run_info(m, Path(tmp), source_faces=faces[m.source])
                   for m in mutants}
    print(f"{len(mutants)} mutated files (seed {SEED}) through `surfprep info FILE --json -`:\n")
    print(outcome_table(results, mutants))
    for name, o in results.items():
        if o.failed:
            print(f"FAILED {name}: {o.kind} {o.stderr.strip()[:300]}")
