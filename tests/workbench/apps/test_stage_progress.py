"""A command's stages on stderr (`StageProgress`): a bar naming the current stage on a terminal, a line per stage
otherwise."""

from __future__ import annotations

import io

from workbench.apps.stage_progress import StageProgress


def test_without_a_terminal_each_stage_is_a_line() -> None:
    stream = io.StringIO()
    with StageProgress("run", 3, stream=stream) as progress:  # a StringIO is no terminal
        assert not progress.terminal
        progress.stage("building")
        progress.stage("simulating 12 m")
    assert stream.getvalue() == "workbench run: building\nworkbench run: simulating 12 m\n"


def test_on_a_terminal_a_bar_counts_the_stages_and_names_the_current_one() -> None:
    stream = io.StringIO()
    progress = StageProgress("run", 3, terminal=True, stream=stream)
    progress.stage("building")
    progress.stage("simulating 12 m")
    assert progress.bar is not None and progress.bar.n == 1
    progress.warn("a warning")
    progress.close()
    text = stream.getvalue()
    assert "run:  33%" in text and "1/3 stages [00:00, simulating 12 m]" in text and "building" in text
    assert "workbench run: " not in text  # no lines: the bar
