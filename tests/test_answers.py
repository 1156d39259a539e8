"""Which answers a tick keeps when more come late (pure: no ROS, no simulator)."""

from __future__ import annotations

from harness.judge.answers import Answers, Received


def _status(text: str, source_ns: int, tick: int | None = None) -> Received:
    return Received(text, 0.01, tick, source_ns=source_ns)


def test_late_statuses_of_a_tick_are_adopted_as_more_answers() -> None:
    """A node that answered a scan twice: both answers are the tick's, so the oracle can
    say it answered twice."""
    answers = Answers(statuses=[_status("Min distance: 1.0 m", 10)])
    rest = answers.take_late([_status("Min distance: 1.0 m", 20, tick=3)], 3)
    assert rest == []
    assert len(answers.statuses) == 2


def test_a_node_that_owed_answers_is_judged_by_its_newest() -> None:
    """A board's first tick: a node behind on the idle stream publishes its old answers
    after the tick's scan went; the newest answer, even one that came late, is the tick's,
    and the older ones (with their Bools) answer no tick."""
    answers = Answers(
        statuses=[_status("No obstacle", 10)],
        warnings=[Received(False, 0.01, source_ns=11)],
        owed_before=True,
    )
    late = [
        _status("No obstacle", 20, tick=0),
        Received(False, 0.02, 0, source_ns=21),
        _status("Min distance: 1.134 m, angle: 3.142 rad", 30, tick=0),
        Received(True, 0.03, 0, source_ns=31),
        _status("Min distance: 1.0 m, angle: 3.142 rad", 40, tick=1),
    ]
    rest = answers.take_late(late, 0)
    assert [r.value for r in answers.statuses] == ["Min distance: 1.134 m, angle: 3.142 rad"]
    assert [r.value for r in answers.warnings] == [True]
    assert {r.tick for r in answers.late} == {None}
    assert len(answers.late) == 4
    assert [r.tick for r in rest] == [1]


def test_late_bools_alone_keep_the_statuses_held() -> None:
    """Only a newer status replaces the one held; a late Bool is simply adopted."""
    answers = Answers(statuses=[_status("No obstacle", 10)], owed_before=True)
    answers.take_late([Received(False, 0.02, 0, source_ns=12)], 0)
    assert [r.value for r in answers.statuses] == ["No obstacle"]
    assert len(answers.warnings) == 1
