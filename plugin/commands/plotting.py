"""What the ``--plot`` options share: loading matplotlib without a display, and
writing a figure with the CLI's error rules (one :class:`OutputFileError` line)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ...errors import OutputFileError

__all__ = ["pyplot", "require_matplotlib", "save_figure"]

_MISSING = "--plot needs matplotlib: pip install 'surfprep[plot]'"


def require_matplotlib() -> None:
    """Raise :class:`OutputFileError` now (before any work) when matplotlib is missing."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise OutputFileError(_MISSING) from None


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the non-interactive Agg backend."""
    require_matplotlib()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save_figure(fig: Any, path: Path) -> Path:
    """Write ``fig`` to ``path`` and close it; the resolved path.

    Raises
    ------
    OutputFileError
        The file cannot be written (folder missing, no permission, ...).
    """
    import matplotlib.pyplot as plt
    try:
        fig.savefig(path, dpi=110)
    except OSError as exc:
        raise OutputFileError(f"cannot write plot {path}: {exc.strerror or exc}") from None
    finally:
        plt.close(fig)
    return Path(path).resolve()
