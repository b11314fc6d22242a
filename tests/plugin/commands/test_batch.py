"""``surfprep batch``: one child process per file, failures recorded, summary, resume, Dask.

The failing children are made deterministic by a stand-in command (``command=``):
a small Python script that, for an input file starting with ``fake:``, does what the
file says (finish, skip faces, fail, hang, crash, run out of memory) and hands every
other file to the real ``python -m surfprep.plugin``, so one batch mixes real samples,
a corrupt STEP file and the failures.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import signal
import sys
import textwrap
from pathlib import Path

import pytest

from surfprep.errors import InputFileError, OutputFileError, SurfprepError
from surfprep.plugin import batch
from surfprep.plugin.commands import base
from surfprep.plugin.commands import batch as batch_command

SAMPLES = Path(__file__).resolve().parents[3] / "step_samples"

STAND_IN = textwrap.dedent('''\
    """A stand-in for ``python -m surfprep.plugin`` (see the test module)."""
    import json, os, resource, signal, subprocess, sys, time
    from pathlib import Path

    args = sys.argv[1:]
    if args[-1:] == ["--help"]:
        raise SystemExit(0 if args[0] in ("info", "heal") else 2)
    verb, source = args[0], Path(args[1])
    head = source.read_bytes()[:64]
    if not head.startswith(b"fake:"):
        os.execv(sys.executable, [sys.executable, "-m", "surfprep.plugin", *args])
    with open(Path(__file__).with_name("runs.log"), "a") as runs:
        runs.write(source.name + "\\n")
    kind, *rest = head[5:].decode().split()
    report = Path(args[args.index("--json") + 1])
    output = Path(args[args.index("-o") + 1]) if "-o" in args else None

    def finish(code, faces):
        block = bytearray(int(rest[0]) << 20) if rest else b""   # touched: resident
        report.write_text(json.dumps({"file": str(source), "n_faces": faces, "size": 2.5,
                                      "valid": True, "options": args[4:], "blocks": [1, 2]}))
        if output is not None:
            output.write_text("model")
        raise SystemExit(code + 0 * len(block))

    if kind == "ok":
        finish(0, 3)
    if kind == "skipped":
        print("surfprep: warning: face 2 skipped: not four-sided", file=sys.stderr)
        finish(1, 5)
    if kind == "error":
        print("surfprep: error: nothing to do in " + source.name, file=sys.stderr)
        raise SystemExit(2)
    if kind == "hang":
        grandchild = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
        source.with_suffix(".grandchild").write_text(str(grandchild.pid))
        time.sleep(600)
    if kind == "crash":
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        os.kill(os.getpid(), signal.SIGSEGV)
    if kind == "memory":
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft == resource.RLIM_INFINITY:
            print("no memory limit was set", file=sys.stderr)
            raise SystemExit(7)
        bytearray(soft)                                          # MemoryError under the limit
    raise SystemExit(9)
''')

#: the mixed batch: real samples, a corrupt file, and the stand-in's cases
MIXED = {"real/synthetic.step": "ok", "real/fuselage.stp": "ok", "corrupt.step": "error",
         "good/one.step": "ok", "good/two.step": "ok", "partial.step": "ok (faces skipped)",
         "refused.step": "error", "hang.step": "timeout", "crash.step": "crashed (signal 11)",
         "memory.step": "memory"}
#: long enough for a real child on a loaded 2-core machine; the hanging child costs this much
MIXED_TIMEOUT_S = 15.0


def _stand_in(folder: Path) -> list[str]:
    script = folder / "stand_in.py"
    script.write_text(STAND_IN)
    return [sys.executable, str(script)]


def _make_inputs(folder: Path) -> None:
    """The files of :data:`MIXED` under ``folder``."""
    contents = {"good/one.step": b"fake: ok 10", "good/two.step": b"fake: ok 150",
                "partial.step": b"fake: skipped", "refused.step": b"fake: error",
                "hang.step": b"fake: hang", "crash.step": b"fake: crash",
                "memory.step": b"fake: memory",
                "corrupt.step": os.urandom(2000).replace(b"ISO", b"iso"),
                "real/synthetic.step": (SAMPLES / "synthetic_named_faces.step").read_bytes(),
                "real/fuselage.stp": (SAMPLES / "occt_fuselage.stp").read_bytes()}
    for name, data in contents.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(data)


def _alive(pid: int) -> bool:
    """True while ``pid`` runs (a zombie waiting for its parent is not running)."""
    stat = Path(f"/proc/{pid}/stat")
    try:
        return stat.read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def _run_mixed(tmp: Path, outdir: Path, **options) -> tuple[batch.BatchResult, list[tuple]]:
    seen: list[tuple] = []
    result = batch.run_batch(
        [str(tmp / "in" / "**" / "*.step"), str(tmp / "in" / "real" / "*.stp")], verb="info",
        outdir=outdir, jobs=2, timeout=MIXED_TIMEOUT_S, memory_limit="3G",
        command=_stand_in(tmp), on_record=lambda r, done, total: seen.append((r, done, total)),
        **options)
    return result, seen


@pytest.fixture(scope="module")
def mixed(tmp_path_factory):
    """The mixed batch run once in the local pool: (inputs folder, result, progress calls)."""
    tmp = tmp_path_factory.mktemp("mixed")
    _make_inputs(tmp / "in")
    result, seen = _run_mixed(tmp, tmp / "out")
    return tmp, result, seen


def test_each_failure_is_recorded_and_the_other_files_finish(mixed):
    tmp, result, seen = mixed
    by_label = {r.label: r for r in result.records}
    assert {label: r.status for label, r in by_label.items()} == MIXED
    assert [r.label for r in result.records] == [                 # input order, each pattern sorted
        "corrupt.step", "crash.step", "good/one.step", "good/two.step", "hang.step", "memory.step",
        "partial.step", "real/synthetic.step", "refused.step", "real/fuselage.stp"]
    assert result.exit_code == 1
    assert by_label["real/synthetic.step"].figures == {"n_faces": 4, "size": pytest.approx(31.2957, abs=1e-4)}
    assert by_label["real/fuselage.stp"].figures["n_faces"] == 8
    assert "is not a STEP file" in by_label["corrupt.step"].message
    assert by_label["corrupt.step"].exit_code == 2
    assert by_label["refused.step"].message == "nothing to do in refused.step"
    assert by_label["partial.step"].message == "face 2 skipped: not four-sided"
    assert by_label["partial.step"].exit_code == 1
    assert by_label["crash.step"].exit_code == -signal.SIGSEGV
    assert by_label["crash.step"].message == "killed by SIGSEGV"
    assert "MemoryError" in by_label["memory.step"].message
    hang = by_label["hang.step"]
    assert MIXED_TIMEOUT_S <= hang.seconds < MIXED_TIMEOUT_S + 5
    grandchild = int((tmp / "in" / "hang.grandchild").read_text())
    assert not _alive(grandchild), "the hanging child's own child outlived the timeout"
    # per-child peak memory from wait4: the 150 MB child is ~140 MB above the 10 MB one,
    # a real child (OCP loaded) far above both
    one, two = by_label["good/one.step"], by_label["good/two.step"]
    assert 120 < two.peak_memory_mb - one.peak_memory_mb < 200
    assert by_label["real/fuselage.stp"].peak_memory_mb > 150
    # only numbers come up from the child's report: no bool, list or string
    assert one.figures == {"n_faces": 3, "size": 2.5}
    assert Path(one.report) == result.outdir / "good__one.info.json"
    assert by_label["refused.step"].report is None
    # one progress call per file, numbered in the order they finished
    assert [done for _, done, _ in seen] == list(range(1, 11))
    assert {total for _, _, total in seen} == {10}
    assert sorted(r.label for r, _, _ in seen) == sorted(MIXED)


def test_the_summary_files_hold_every_record(mixed):
    _, result, _ = mixed
    listed = json.loads(result.summary_json.read_text())
    assert listed == [r.as_dict() for r in result.records]
    with open(result.summary_csv, newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) == len(listed) == 10
    figures = sorted({k for r in listed for k in r["figures"]})
    assert figures == ["n_faces", "size"]
    expected_columns = [k for k in listed[0] if k != "figures"] + [f"figures.{k}" for k in figures]
    assert list(rows[0]) == expected_columns
    for row, record in zip(rows, listed):
        for key in expected_columns:
            value = record["figures"].get(key[8:]) if key.startswith("figures.") else record[key]
            text = "" if value is None else ";".join(value) if isinstance(value, list) else str(value)
            assert row[key] == text, key
    assert [r["status"] for r in listed].count("ok") == 4
    assert not list(result.outdir.glob(".*.tmp")), "a temporary file was left behind"


def test_a_dask_cluster_gives_the_statuses_of_the_local_pool(mixed):
    distributed = pytest.importorskip("dask.distributed")
    tmp, local, _ = mixed
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        result, seen = _run_mixed(tmp, tmp / "out-dask", scheduler=cluster.scheduler_address)
    assert result.scheduler == cluster.scheduler_address
    assert [(r.label, r.status) for r in result.records] == \
        [(r.label, r.status) for r in local.records]
    assert [(r.label, r.figures) for r in result.records] == \
        [(r.label, r.figures) for r in local.records]
    assert len(seen) == 10 and result.exit_code == 1
    assert json.loads(result.summary_json.read_text()) == [r.as_dict() for r in result.records]


def test_resume_skips_the_files_done_and_runs_the_others_again(tmp_path):
    command = _stand_in(tmp_path)
    (tmp_path / "in").mkdir()
    for name, text in (("a.step", "fake: ok"), ("b.step", "fake: skipped"), ("c.step", "fake: error")):
        (tmp_path / "in" / name).write_text(text)
    pattern, out, runs = str(tmp_path / "in" / "*.step"), tmp_path / "out", tmp_path / "runs.log"
    first = batch.run_batch([pattern], verb="heal", outdir=out, jobs=2, timeout=30, command=command)
    assert [r.status for r in first.records] == ["ok", "ok (faces skipped)", "error"]
    assert [Path(p).name for p in first.records[0].outputs] == ["a.heal.step"]
    assert sorted(runs.read_text().split()) == ["a.step", "b.step", "c.step"]
    runs.unlink()
    second = batch.run_batch([pattern], verb="heal", outdir=out, jobs=2, timeout=30,
                             command=command, resume=True)
    assert [r.status for r in second.records] == ["skipped (done)", "skipped (done)", "error"]
    assert runs.read_text().split() == ["c.step"], "a file done before was run again"
    kept = second.records[0]
    assert kept.figures == {"n_faces": 3, "size": 2.5} and kept.seconds == first.records[0].seconds
    assert kept.outputs == first.records[0].outputs and second.exit_code == 1
    listed = json.loads((out / "summary.json").read_text())
    assert [r["status"] for r in listed] == ["skipped (done)", "skipped (done)", "error"]
    # another verb's reports do not count as done
    runs.unlink()
    third = batch.run_batch([pattern], verb="info", outdir=out, jobs=2, timeout=30,
                            command=command, resume=True)
    assert [r.status for r in third.records] == ["ok", "ok (faces skipped)", "error"]
    assert sorted(runs.read_text().split()) == ["a.step", "b.step", "c.step"]


def test_a_file_that_failed_before_is_not_done_even_with_a_stale_report(tmp_path):
    command = _stand_in(tmp_path)
    source = tmp_path / "in" / "a.step"
    source.parent.mkdir()
    source.write_text("fake: ok")
    out = tmp_path / "out"
    assert batch.run_batch([source], verb="info", outdir=out, command=command).exit_code == 0
    source.write_text("fake: error")
    failed = batch.run_batch([source], verb="info", outdir=out, command=command)
    assert failed.records[0].status == "error"
    assert not (out / "a.info.json").exists(), "the earlier run's report was left in place"
    source.write_text("fake: ok")
    (out / "a.info.json").write_text("{}")                       # a report from elsewhere
    again = batch.run_batch([source], verb="info", outdir=out, command=command, resume=True)
    assert again.records[0].status == "ok"                        # the summary said: failed


def _batch_cli(capsys, *argv) -> tuple[int, str, str]:
    """``surfprep batch ARGV`` through the real command line once batch is registered there,
    else through a parser built the same way (subcommand parser, one-line errors, exit 2)."""
    from surfprep.plugin.commands import COMMANDS
    if any(c.name == "batch" for c in COMMANDS):
        from helpers.cli import run
        return run(capsys, "batch", *argv)
    parser = argparse.ArgumentParser(prog="surfprep")
    sub = parser.add_subparsers(dest="command")
    batch_command.COMMAND.add_arguments(sub.add_parser("batch"))
    try:
        args = parser.parse_args(["batch", *map(str, argv)])
        code = batch_command.COMMAND.run(args, base.Console.for_streams(progress=False))
    except SystemExit as exit_:
        code = exit_.code
    except SurfprepError as exc:
        print(f"surfprep: error: {exc}", file=sys.stderr)
        code = 2
    out, err = capsys.readouterr()
    return code, out, err


def test_the_command_line_runs_a_verb_with_its_options_and_unique_names(tmp_path, capsys):
    for folder in ("a", "b"):
        (tmp_path / "parts" / folder).mkdir(parents=True)
        (tmp_path / "parts" / folder / "x.step").write_bytes(
            (SAMPLES / "synthetic_named_faces.step").read_bytes())
    out = tmp_path / "out"
    code, stdout, err = _batch_cli(capsys, str(tmp_path / "parts" / "**" / "*.step"), "--do", "grid",
                                   "-o", out, "--jobs", "2", "--", "--dims", "5", "7")
    assert code == 0, err
    assert sorted(p.name for p in out.glob("*.cgns")) == ["a__x.cgns", "b__x.cgns"]
    for name in ("a__x", "b__x"):
        report = json.loads((out / f"{name}.grid.json").read_text())
        assert report["blocks"] and all(b["dims"] == [5, 7] for b in report["blocks"])
    listed = json.loads((out / "summary.json").read_text())
    assert [Path(r["outputs"][0]).name for r in listed] == ["a__x.cgns", "b__x.cgns"]
    status = listed[0]["status"]                      # the cylinder is not four-sided: skipped
    assert status == "ok (faces skipped)" and listed[1]["status"] == status
    progress = [line for line in err.splitlines() if line.startswith("[")]
    assert [line.split()[0] for line in progress] == ["[1/2]", "[2/2]"]     # as they finish
    assert sorted(line.split()[1] for line in progress) == ["a/x.step", "b/x.step"]
    assert all(line.endswith(" s") and f" {status} " in line for line in progress)
    table = stdout.splitlines()
    assert table[0].split() == ["file", "status", "seconds", "MB"]
    assert [line.split()[0] for line in table[1:3]] == ["a/x.step", "b/x.step"]
    assert all(f" {status} " in line for line in table[1:3])


#: ``surfprep batch ARGV`` in a fresh interpreter: exit code, stdout, stderr and which heavy
#: modules the batch process itself loaded (its children load OpenCascade, it must not)
_FRESH_BATCH = """
import contextlib, io, json, sys
from surfprep.plugin import cli
from surfprep.plugin.commands import batch
if all(c.name != "batch" for c in cli.COMMANDS):
    cli.COMMANDS = (*cli.COMMANDS, batch.COMMAND)
out, err = io.StringIO(), io.StringIO()
with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
    code = cli.main(["batch", *sys.argv[1:]])
print(json.dumps({"code": code, "out": out.getvalue(), "err": err.getvalue(), "loaded":
                  [m for m in ("OCP", "numba", "scipy", "surfprep.algorithms") if m in sys.modules]}))
"""


def test_json_dash_prints_the_batch_report_and_the_batch_loads_no_opencascade(tmp_path):
    import subprocess
    source = tmp_path / "part.step"
    source.write_bytes((SAMPLES / "synthetic_named_faces.step").read_bytes())
    done = subprocess.run([sys.executable, "-c", _FRESH_BATCH, str(source), "--do", "info", "-o",
                           str(tmp_path / "out"), "--json", "-"],
                          capture_output=True, text=True, timeout=300, check=True)
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["code"] == 0, result["err"]
    report = json.loads(result["out"])
    assert report["counts"] == {"ok": 1} and report["files"][0]["figures"]["n_faces"] == 4
    assert report["n_files"] == 1 and result["err"].count("[1/1] part.step ok") == 1
    assert result["loaded"] == []


def test_no_match_is_one_line_and_exit_2(tmp_path, capsys):
    code, stdout, err = _batch_cli(capsys, str(tmp_path / "*.step"), "--do", "info", "-o",
                                   tmp_path / "out")
    assert code == 2 and stdout == ""
    assert err.strip().splitlines() == [f"surfprep: error: no file matches '{tmp_path / '*.step'}'"]
    assert not (tmp_path / "out").exists()


def test_an_outdir_that_is_a_file_is_refused_before_any_child_starts(tmp_path):
    command = _stand_in(tmp_path)
    (tmp_path / "a.step").write_text("fake: ok")
    blocker = tmp_path / "out"
    blocker.write_text("not a folder")
    with pytest.raises(OutputFileError, match="is a file, not a folder"):
        batch.run_batch([tmp_path / "a.step"], verb="info", outdir=blocker, command=command)
    assert not (tmp_path / "runs.log").exists()
    assert blocker.read_text() == "not a folder"


def test_errors_before_the_work(tmp_path, monkeypatch):
    command = _stand_in(tmp_path)
    source = tmp_path / "a.step"
    source.write_text("fake: ok")
    out = tmp_path / "out"
    with pytest.raises(SurfprepError, match="'prepare' is not a command of this surfprep"):
        batch.run_batch([source], verb="prepare", outdir=out, command=command)
    with pytest.raises(SurfprepError, match="the batch sets --json"):
        batch.run_batch([source], verb="info", outdir=out, options=["--js", "r.json"], command=command)
    with pytest.raises(SurfprepError, match="names each file's output"):
        batch.run_batch([source], verb="heal", outdir=out, options=["-ox.step"], command=command)
    with pytest.raises(InputFileError, match="does not exist"):
        batch.run_batch([tmp_path / "missing.step"], verb="info", outdir=out, command=command)
    with pytest.raises(InputFileError, match="is a folder"):
        batch.run_batch([tmp_path], verb="info", outdir=out, command=command)
    monkeypatch.setitem(sys.modules, "dask", None)
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    with pytest.raises(SurfprepError, match=r'pip install "surfprep\[batch\]"'):
        batch.run_batch([source], verb="info", outdir=out, scheduler="tcp://127.0.0.1:1",
                        command=command)
    assert not (tmp_path / "runs.log").exists()


def test_outputs_of_a_pattern_run_are_not_inputs_of_the_next(tmp_path):
    command = _stand_in(tmp_path)
    (tmp_path / "a.step").write_text("fake: ok")
    out = tmp_path / "out"
    first = batch.run_batch([tmp_path / "**" / "*.step"], verb="heal", outdir=out, command=command)
    assert (out / "a.heal.step").is_file()
    again = batch.run_batch([tmp_path / "**" / "*.step"], verb="heal", outdir=out, command=command)
    assert [r.label for r in again.records] == [r.label for r in first.records] == ["a.step"]


def test_names_are_unique_and_follow_the_relative_path(tmp_path):
    files = [tmp_path / "p" / "part.step", tmp_path / "p" / "part.igs",
             tmp_path / "p" / "sub" / "part.step", tmp_path / "p" / "other.stp"]
    jobs = batch.plan_jobs(files, verb="grid", outdir=tmp_path / "out")
    assert [j.name for j in jobs] == ["part_step", "part_igs", "sub__part", "other"]
    assert [j.label for j in jobs] == ["part.step", "part.igs", "sub/part.step", "other.stp"]
    assert jobs[2].outputs == (tmp_path / "out" / "sub__part.cgns",)
    assert jobs[2].arguments == ("grid", str(files[2]), "-o", str(tmp_path / "out" / "sub__part.cgns"),
                                 "--json", str(tmp_path / "out" / "sub__part.grid.json"))
    info = batch.plan_jobs(files[:1], verb="info", outdir=tmp_path / "out", options=["--heal"])
    assert info[0].outputs == () and info[0].arguments[-1] == "--heal"
    assert batch.FileJob.from_dict(json.loads(json.dumps(jobs[2].as_dict()))) == jobs[2]


def test_memory_sizes():
    assert batch.parse_memory_size("4G") == 4 << 30
    assert batch.parse_memory_size("500m") == 500 << 20
    assert batch.parse_memory_size("1.5GiB") == 3 << 29
    assert batch.parse_memory_size("2048") == 2048
    for bad in ("", "G", "-1G", "lots", "0"):
        with pytest.raises(ValueError):
            batch.parse_memory_size(bad)


def test_the_batch_command_module_is_light_at_import():
    import subprocess
    code = ("import sys, surfprep.plugin.commands.batch; "
            "print(' '.join(m for m in ('surfprep.plugin.batch', 'dask') if m in sys.modules))")
    shown = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert shown.stdout.strip() == ""


def test_peak_memory_is_the_files_own_from_a_large_process(tmp_path):
    """Run from a process holding 400 MB (a test worker, a Dask worker), each file still
    reports its own peak: a fork of the batch process would start at the batch's size."""
    import numpy as np
    ballast = np.ones(50_000_000)                       # 400 MB, touched
    _make_inputs(tmp_path / "in")
    result = batch.run_batch([str(tmp_path / "in" / "good" / "*.step")], verb="info",
                             outdir=tmp_path / "out", jobs=2, timeout=MIXED_TIMEOUT_S,
                             command=_stand_in(tmp_path))
    one, two = sorted(result.records, key=lambda r: r.label)
    assert ballast.sum() == 50_000_000
    assert one.peak_memory_mb < 100
    assert 120 < two.peak_memory_mb - one.peak_memory_mb < 200
    assert not list((tmp_path / "out").glob("*.peak"))  # the launcher's notes are cleared
