"""The command line: the group and its error handling (:mod:`.main`), one module per command."""

from __future__ import annotations

from .main import (
    cli, COMMANDS, in_cli_words, LazyGroup, main
)

__all__ = [
    "COMMANDS", "LazyGroup", "cli", "in_cli_words", "main"
]
