"""envelope.progress: a tqdm bar in an ordinary process; where a sink is set, a bar that
sends its progress there, at most every SEND_EVERY_S and once more on close."""

import pytest
from tqdm import tqdm

import envelope.progress as progress_module
from envelope.progress import SEND_EVERY_S, Progress, progress_bar, send_progress_to


class Clock:
    def __init__(self):
        self.now_s = 100.0

    def monotonic(self):
        return self.now_s


@pytest.fixture
def sent(monkeypatch):
    clock, reports = Clock(), []
    monkeypatch.setattr(progress_module, "time", clock)
    send_progress_to(reports.append)
    yield clock, reports
    send_progress_to(None)


def test_without_a_sink_it_is_tqdm():
    bar = progress_bar(total=3, desc="x", disable=True)
    assert isinstance(bar, tqdm)
    bar.close()


def test_a_sent_bar_reports_at_most_every_interval_and_on_close(sent):
    clock, reports = sent
    with progress_bar(total=10, desc="neural3d a", initial=2, dynamic_ncols=True) as bar:
        for _ in range(6):  # a step every SEND_EVERY_S / 4 (exact in binary)
            clock.now_s += SEND_EVERY_S / 4
            bar.update()
        bar.set_postfix(loss="0.0123", psnr="24.50")
    # Sent at the first update, then four steps (SEND_EVERY_S) later, then on close.
    assert [r.done for r in reports] == [3, 7, 8]
    assert reports[-1] == Progress("neural3d a", 8, 10, 2, 1.5 * SEND_EVERY_S,
                                   "loss=0.0123, psnr=24.50")
    assert reports[-1].rate_per_s == pytest.approx(6 / (1.5 * SEND_EVERY_S))
    assert reports[-1].left_s == pytest.approx(2 / reports[-1].rate_per_s)


def test_rate_and_time_left_need_steps_and_a_total():
    assert Progress("x", 5, None, 5, 1.0).rate_per_s is None
    assert Progress("x", 6, None, 5, 1.0).left_s is None
    assert Progress("x", 6, 9, 5, 2.0).left_s == 6.0
