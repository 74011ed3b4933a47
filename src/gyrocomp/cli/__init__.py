"""The command line: the group and its error handling (:mod:`.entry_point`), one module per command."""

from __future__ import annotations

from .entry_point import cli, COMMANDS, in_cli_words, LazyGroup, main

__all__ = ["COMMANDS", "LazyGroup", "cli", "in_cli_words", "main"]
