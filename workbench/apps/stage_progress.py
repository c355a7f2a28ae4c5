"""A command's stages shown on stderr while it works (`StageProgress`), so that a long `workbench run` is never
silent: on a terminal a bar counting the stages with the current one named on it (as `compare`'s bar counts its
runs; the simulator's own bar of metres shows below it), otherwise one line per stage ("workbench run: simulating
..."), which a log or a CI job keeps.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TextIO

from tqdm import tqdm

from workbench.base.console import warn_on_stderr

#: The bar: the stages done of all, the time since the command started and the current stage (no rate: stages
#: differ in length).
BAR_FORMAT = "{l_bar}{bar}| {n_fmt}/{total_fmt} stages [{elapsed}{postfix}]"


class StageProgress:
    """The stages of `command` (`stages` of them) on `stream` (default: stderr): `stage(text)` starts the next one.
    terminal: a bar (None: when the stream is a terminal); False: one line per stage. Use it as a context manager,
    or `close()` it."""

    def __init__(self, command: str, stages: int, terminal: bool | None = None, stream: TextIO | None = None) -> None:
        self.command = command
        self.stream = stream if stream is not None else sys.stderr
        self.terminal = self.stream.isatty() if terminal is None else terminal
        self.started = 0
        self.bar = (
            tqdm(total=stages, desc=command, leave=False, file=self.stream, bar_format=BAR_FORMAT)
            if self.terminal
            else None
        )

    def stage(self, text: str) -> None:
        """Start the next stage: name it on the bar, or write its line.

        Parameters
        ----------
        text : str
            The stage in words, e.g. "Figure 6: rollover limits".
        """
        if self.bar is not None:
            if self.started:
                self.bar.update(1)
            self.bar.set_postfix_str(text)
        else:
            print(f"workbench {self.command}: {text}", file=self.stream, flush=True)
        self.started += 1

    @contextmanager
    def above(self) -> Iterator[None]:
        """Write messages (warnings) above the bar rather than through it.

        Yields
        ------
        None
            Inside the ``with`` block, writes to the stream go above the bar.
        """
        if self.bar is None:
            yield
        else:
            with tqdm.external_write_mode(file=self.stream):
                yield

    def warn(self, message: str) -> None:
        """A warning on stderr (`warn_on_stderr`), above the bar.

        Parameters
        ----------
        message : str
            The warning, one line.
        """
        with self.above():
            warn_on_stderr(message)

    def close(self) -> None:
        """Take the bar off the screen (lines stay as written)."""
        if self.bar is not None:
            self.bar.close()

    def __enter__(self) -> StageProgress:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()


__all__ = ["StageProgress"]
