"""The subcommands of the ``surfprep`` command line, one module each.

To add a subcommand: write ``plugin/commands/<name>.py`` defining
``COMMAND = Command(...)`` (see :mod:`.base`) and list it in :data:`COMMANDS`.
"""

from __future__ import annotations

from . import batch, compose, demo, grid, heal, info, intersect, prepare, reparam, split
from .base import Command, Console

__all__ = ["COMMANDS", "Command", "Console"]

#: Every subcommand, in the order ``surfprep --help`` lists them.
COMMANDS: tuple[Command, ...] = (info.COMMAND, demo.COMMAND, prepare.COMMAND, intersect.COMMAND,
                                 heal.COMMAND, reparam.COMMAND, grid.COMMAND,
                                 split.COMMAND, compose.COMMAND, batch.COMMAND)
