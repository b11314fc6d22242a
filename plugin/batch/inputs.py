"""The files of a batch: patterns expanded (:func:`expand_inputs`), OUTDIR checked
(:func:`prepare_outdir`), one :class:`~surfprep.plugin.batch.records.FileJob` per file
with unique output names (:func:`plan_jobs`), and the checks made before the first
file runs (:func:`check_passthrough`, :func:`verb_is_available`).
"""

from __future__ import annotations

import glob
import os
import subprocess
import tempfile
from collections import Counter
from collections.abc import Mapping, Sequence
from pathlib import Path

from ...errors import InputFileError, OutputFileError, SurfprepError
from .records import FileJob, default_command

__all__ = [
    "RESERVED_OPTIONS",
    "VERB_OUTPUTS",
    "check_passthrough",
    "default_jobs",
    "expand_inputs",
    "plan_jobs",
    "prepare_outdir",
    "verb_is_available",
]

#: per verb, the suffix of its model/grid output in OUTDIR (None: the JSON report only)
VERB_OUTPUTS: Mapping[str, str | None] = {
    "info": None,
    "heal": ".heal.step",
    "reparam": ".reparam.step",
    "intersect": ".intersect.step",
    "split": ".split.step",
    "prepare": ".prepare.step",
    "grid": ".cgns",
}

#: options of the per-file command that the batch sets itself (refused after ``--``)
RESERVED_OPTIONS = ("--output", "--json", "--plot")


# ----------------------------------------------------------------- settings
def default_jobs() -> int:
    """The number of cores this process may run on (the default ``--jobs``)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def check_passthrough(options: Sequence[str]) -> None:
    """Refuse per-file options that the batch sets itself (``-o``, ``--json``, ``--plot``).

    Raises
    ------
    SurfprepError
        One of ``options`` (or an abbreviation argparse would accept) names an output.
    """
    for option in options:
        if option == "-o" or (option.startswith("-o") and not option.startswith("--")):
            raise SurfprepError(f"option {option!r} after '--': the batch names each file's "
                                "output itself (OUTDIR/<name>.<verb>...)")
        name = option.split("=", 1)[0]
        if name.startswith("--") and len(name) > 3:
            for reserved in RESERVED_OPTIONS:
                if reserved.startswith(name):
                    raise SurfprepError(f"option {option!r} after '--': the batch sets {reserved} "
                                        "for each file itself (OUTDIR/<name>.<verb>...)")


def verb_is_available(verb: str, *, command: Sequence[str] | None = None,
                      timeout_s: float = 120.0) -> bool:
    """True when ``command VERB --help`` succeeds, i.e. the children's ``surfprep`` has VERB.

    The children's own command line answers (the commands it registers), so a verb
    added to :mod:`surfprep.plugin.commands` later (``prepare``) is found without
    this module knowing the list.

    Raises
    ------
    SurfprepError
        The command cannot be started or does not answer within ``timeout_s``.
    """
    argv = [*(default_command() if command is None else command), verb, "--help"]
    try:
        completed = subprocess.run(argv, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL, timeout=timeout_s, check=False)
    except OSError as exc:
        raise SurfprepError(f"cannot start {argv[0]}: {exc.strerror or exc}") from None
    except subprocess.TimeoutExpired:
        raise SurfprepError(f"'{' '.join(argv)}' did not answer within {timeout_s:g} s") from None
    return completed.returncode == 0


# ------------------------------------------------------------------ inputs
def expand_inputs(patterns: Sequence[str | os.PathLike[str]], *,
                  exclude: Path | None = None) -> tuple[Path, ...]:
    """The files that ``patterns`` name, absolute, each once, in the order given.

    Parameters
    ----------
    patterns : sequence of str or path
        Glob patterns (``**`` matches folders recursively; each pattern's matches are
        sorted) or plain paths of files.
    exclude : Path, optional
        A folder whose files a pattern never matches (OUTDIR: the outputs of an earlier
        run are not inputs).

    Returns
    -------
    tuple of Path
        Possibly empty when no pattern matched a file.

    Raises
    ------
    InputFileError
        A plain path (no ``*?[``) that is not an existing file.
    """
    excluded = None if exclude is None else exclude.resolve()
    found: dict[Path, None] = {}
    for pattern in patterns:
        text = os.fspath(pattern)
        if glob.has_magic(text):
            matches = sorted(Path(p) for p in glob.glob(text, recursive=True))
            for path in matches:
                resolved = path.resolve()
                if path.is_file() and not (excluded is not None and excluded in resolved.parents):
                    found.setdefault(resolved)
            continue
        path = Path(text)
        if path.is_dir():
            raise InputFileError(f"input {text} is a folder; give a pattern such as "
                                 f"'{Path(text) / '**' / '*.step'}'")
        if not path.is_file():
            raise InputFileError(f"input file {text} does not exist")
        found.setdefault(path.resolve())
    return tuple(found)


def prepare_outdir(outdir: str | os.PathLike[str]) -> Path:
    """Create OUTDIR if missing and check that files can be written in it.

    Returns
    -------
    Path
        The folder, absolute.

    Raises
    ------
    OutputFileError
        It is a file, cannot be created, or a file cannot be written in it.
    """
    folder = Path(outdir).absolute()
    if folder.exists() and not folder.is_dir():
        raise OutputFileError(f"output folder {outdir} is a file, not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe, name = tempfile.mkstemp(prefix=".surfprep-batch.", suffix=".probe", dir=folder)
        os.close(probe)
        os.unlink(name)
    except OSError as exc:
        raise OutputFileError(f"cannot write in the output folder {outdir}: "
                              f"{exc.strerror or exc}") from None
    return folder


def plan_jobs(files: Sequence[Path], *, verb: str, outdir: Path,
              options: Sequence[str] = ()) -> tuple[FileJob, ...]:
    """One :class:`FileJob` per file, with output names unique in the batch.

    A file's name is its path relative to the files' common folder, folders joined by
    ``__`` and without the suffix (``a/part.step`` and ``b/part.step`` give ``a__part``
    and ``b__part``); files that would still share a name keep their suffix
    (``part_step``, ``part_igs``).

    Parameters
    ----------
    files : sequence of Path
        Absolute input files (:func:`expand_inputs`).
    verb : str
        A key of :data:`VERB_OUTPUTS`.
    outdir : Path
        Absolute output folder.
    options : sequence of str
        Options appended to every child's command line (after ``--``).

    Raises
    ------
    SurfprepError
        An unknown verb.
    OutputFileError
        An output of one file would replace another input.
    """
    if verb not in VERB_OUTPUTS:
        raise SurfprepError(f"unknown verb {verb!r}; expected one of {', '.join(VERB_OUTPUTS)}")
    labels, names = _names(files)
    suffix = VERB_OUTPUTS[verb]
    jobs = []
    for source, label, name in zip(files, labels, names):
        outputs = () if suffix is None else (outdir / f"{name}{suffix}",)
        report, log = outdir / f"{name}.{verb}.json", outdir / f"{name}.{verb}.log"
        output_options = [arg for out in outputs for arg in ("-o", str(out))]
        arguments = (verb, str(source), *output_options, "--json", str(report), *options)
        jobs.append(FileJob(source=source, label=label, name=name, verb=verb, report=report,
                            log=log, outputs=outputs, arguments=arguments))
    inputs = set(files)
    for job in jobs:
        for target in (*job.outputs, job.report, job.log):
            if target.resolve() in inputs:
                raise OutputFileError(f"the output {target} of {job.label} would replace an "
                                      "input file; choose another OUTDIR")
    return tuple(jobs)


def _names(files: Sequence[Path]) -> tuple[list[str], list[str]]:
    """Display labels and unique output names of ``files`` (see :func:`plan_jobs`)."""
    if not files:
        return [], []
    base = Path(os.path.commonpath([str(f.parent) for f in files]))
    relative = [f.relative_to(base) for f in files]
    labels = [r.as_posix() for r in relative]
    names = ["__".join(r.with_suffix("").parts) for r in relative]
    clashes = Counter(names)
    names = [("__".join(r.parts).replace(".", "_") if clashes[n] > 1 else n)
             for r, n in zip(relative, names)]
    unique: list[str] = []
    taken: set[str] = set()
    for n in names:
        candidate, k = n, 2
        while candidate in taken:
            candidate, k = f"{n}-{k}", k + 1
        taken.add(candidate)
        unique.append(candidate)
    return labels, unique
