"""The ``surfprep`` command line run in-process, its output captured."""

from __future__ import annotations

from surfprep.plugin import cli


def run(capsys, *argv) -> tuple[int, str, str]:
    """``surfprep ARGV...`` (arguments turned into strings): exit code, stdout, stderr."""
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err
