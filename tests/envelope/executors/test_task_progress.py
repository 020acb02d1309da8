"""envelope.executors.task_progress: the running tasks' progress, as tqdm bars on a terminal and
as plain lines, at most one per task every ``every_s``, elsewhere."""

from envelope.executors.task_progress import TaskProgressLines, progress_line
from envelope.progress import Progress


class Clock:
    def __init__(self):
        self.now_s = 0.0

    def __call__(self):
        return self.now_s


def test_lines_when_not_a_terminal_at_most_every_interval(capsys):
    clock = Clock()
    show = TaskProgressLines(interactive=False, every_s=30.0, clock=clock)
    for t_s, done in ((0.0, 10), (10.0, 20), (31.0, 40), (40.0, 50)):
        clock.now_s = t_s
        show(0, Progress("neural3d a", done, 100, 0, 2.0 * done / 10, "loss=0.0100"))
        show(1, Progress("neural3d b", done, None, 0, 0.0))
    show(0, None)
    clock.now_s = 41.0
    show(0, Progress("neural3d a", 60, 100, 0, 12.0))  # a task index used again: a new task
    lines = capsys.readouterr().err.splitlines()
    assert lines == [
        "neural3d a: 10/100 steps, 5.0 steps/s, 00:18 left; loss=0.0100",
        "neural3d b: 10 steps",
        "neural3d a: 40/100 steps, 5.0 steps/s, 00:12 left; loss=0.0100",
        "neural3d b: 40 steps",
        "neural3d a: 60/100 steps, 5.0 steps/s, 00:08 left",
    ]


def test_a_bar_per_running_task_on_a_terminal():
    show = TaskProgressLines(interactive=True)
    show(3, Progress("neural3d a", 5, 100, 2, 1.0, "loss=0.5"))
    show(3, Progress("neural3d a", 40, 100, 2, 8.0, "loss=0.1"))
    show(4, Progress("neural3d b", 1, 50, 0, 0.1))
    bar = show.bars[3]
    assert (bar.n, bar.total, bar.desc, bar.postfix) == (40, 100, "neural3d a", "loss=0.1")
    show(3, None)
    assert set(show.bars) == {4}
    show.close()
    assert show.bars == {}


def test_a_line_without_steps_yet_says_only_where_it_stands():
    assert progress_line(Progress("x", 7, 9, 7, 3.0)) == "x: 7/9 steps"
