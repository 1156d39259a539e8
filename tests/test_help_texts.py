"""Every command's --help: one name and one metavar per option, defaults that are the
parser's, descriptions, and the claims the help makes about what a command does."""

from __future__ import annotations

import argparse
import io
import re

import pytest
from rich.console import Console

from harness.cli import build_parser, main
from harness.commands import arguments, sim, sweep
from harness.commands.arguments import FAULTS_METAVAR

#: Options that take another kind of value in one command, on purpose.
DIFFERS_ON_PURPOSE = {
    "--scenario": "emulate serves one scenario; grade and sweep take several",
    "--record": "sim also takes a folder (WORLD.mcap in it); replay a file",
    # issue 28 names both: grade writes one results.json per student into --out, run one
    # for one submission wherever FILE says
    "--gradescope": "grade: a flag (a file per student in --out); run: FILE",
}


def commands() -> dict[str, argparse.ArgumentParser]:
    (sub,) = [a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(sub.choices)


def shown_options(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    """The options --help lists (hidden ones are kept for old scripts, not shown)."""
    return [
        a
        for a in parser._actions
        if a.option_strings
        and a.help != argparse.SUPPRESS
        and not isinstance(a, argparse._HelpAction)
    ]


def value_shape(action: argparse.Action) -> str:
    """How --help shows the option's value: its metavar, or nothing for a flag."""
    if action.nargs == 0:
        return "(flag)"
    if action.metavar is not None:
        return str(action.metavar)
    if action.choices is not None:
        return "{" + ",".join(map(str, action.choices)) + "}"
    return action.dest.upper()


def help_of(command: str, capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    return " ".join(capsys.readouterr().out.split())  # argparse wraps lines


def test_every_command_has_a_description(capsys: pytest.CaptureFixture[str]) -> None:
    """`X --help` says what X does, list and ports included (they take no options)."""
    for name, parser in commands().items():
        assert parser.description, f"{name} --help has no description"
    assert "LIDAR it simulates" in help_of("list", capsys)
    assert "whether you may open it" in help_of("ports", capsys)


def test_faults_has_one_metavar_in_every_command() -> None:
    found = {
        name: value_shape(action)
        for name, parser in commands().items()
        for action in shown_options(parser)
        if "--faults" in action.option_strings
    }
    assert set(found) == {"run", "sim", "emulate", "replay", "grade", "sweep"}
    assert set(found.values()) == {FAULTS_METAVAR}, found


def test_an_option_shows_one_kind_of_value_in_every_command() -> None:
    """The same option is a flag everywhere or takes the same METAVAR everywhere
    (run --animate is a flag: sim's file option is --animation)."""
    shapes: dict[str, dict[str, str]] = {}
    for name, parser in commands().items():
        for action in shown_options(parser):
            for option in action.option_strings:
                shapes.setdefault(option, {})[name] = value_shape(action)
    mixed = {
        option: by_command
        for option, by_command in shapes.items()
        if len(set(by_command.values())) > 1 and option not in DIFFERS_ON_PURPOSE
    }
    assert not mixed, mixed


def _literal(value: object) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def test_a_default_the_parser_has_is_the_one_the_help_names() -> None:
    """An option with a default of its own says it; a literal after "(default " (no colon:
    a colon introduces a default resolved at run time) is the parser's default."""
    for name, parser in commands().items():
        for action in parser._actions:
            if action.help in (None, argparse.SUPPRESS) or isinstance(action, argparse._HelpAction):
                continue
            label = f"{name} {'/'.join(action.option_strings) or action.dest}"
            default = action.default
            if default not in (None, False, [], argparse.SUPPRESS):
                assert "default" in action.help and _literal(default) in action.help, label
            for claimed in re.findall(r"\(default ([^\s;:),]+)", action.help):
                assert claimed.removeprefix("./") == _literal(default), (label, claimed)


def test_the_domain_help_names_the_range_the_reservation_uses() -> None:
    from harness.ros.domain import FIRST_ID, LAST_ID

    assert f"a free one in {FIRST_ID}..{LAST_ID}" in arguments.DOMAIN_HELP


def test_sim_says_its_domain_is_the_shells(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """sim joins the shell's ROS_DOMAIN_ID (so teleop and rviz2 see the robot), as its help
    says; run and replay reserve a free one."""
    assert "the shell's ROS_DOMAIN_ID, else 0" in help_of("sim", capsys)
    assert "free one" not in help_of("sim", capsys)
    monkeypatch.setenv("ROS_DOMAIN_ID", "7")
    assert sim._domain(None) == 7
    monkeypatch.delenv("ROS_DOMAIN_ID")
    assert sim._domain(None) == 0
    assert sim._domain(42) == 42
    assert "a free one in 1..101, reserved for each scenario" in help_of("run", capsys)


def test_options_a_command_refuses_are_not_listed(capsys: pytest.CaptureFixture[str]) -> None:
    """sim always runs in real time and a sweep reserves a domain per run: their
    --realtime and --domain-id are refused with a reason, and not offered in --help."""
    assert "--realtime" not in help_of("sim", capsys)
    assert main(["sim", "--realtime"]) == 2
    assert "always runs in real time" in capsys.readouterr().err
    assert "--domain-id" not in help_of("sweep", capsys)
    assert "--domain-id" not in help_of("grade", capsys)
    assert "instead of lockstep" not in help_of("run", capsys)


def test_replay_names_its_own_defaults(capsys: pytest.CaptureFixture[str]) -> None:
    """A replay has no scenario: the threshold is the recording's, the warning rule optional."""
    text = help_of("replay", capsys)
    assert "scenario's" not in text
    assert "(default: the recording's; a robot's rosbag2 has none, so give it)" in text
    assert "required (default: optional)" in text


def test_sim_record_and_animation_say_what_they_write(capsys: pytest.CaptureFixture[str]) -> None:
    text = help_of("sim", capsys)
    assert "--record FILE.mcap|DIR" in text and "WORLD.mcap in the folder DIR" in text
    assert "--animation FILE" in text and "FILE.gif" in text
    assert "--animate" not in text  # run's --animate is a flag; sim's old name is hidden


def test_old_spellings_still_parse() -> None:
    parsers = commands()
    old = parsers["sim"].parse_args(["--animate", "s.gif"])
    new = parsers["sim"].parse_args(["--animation", "s.gif"])
    assert old.animation == new.animation == "s.gif"
    assert parsers["sweep"].parse_args(["--seeds", "3"]).seeds == 3
    assert parsers["sweep"].parse_args(["--seed-count", "3"]).seeds == 3


def test_sweep_seed_is_not_taken_for_a_seed_count(capsys: pytest.CaptureFixture[str]) -> None:
    """argparse takes a prefix of an option for the option: `--seed 3` once meant seeds
    0..2. Now it is refused, naming --seed-count."""
    assert main(["sweep", "--seed", "3"]) == 2
    err = capsys.readouterr().err
    assert "ambiguous option: --seed" in err and "--seed-count" in err


def test_sweep_scenario_is_repeatable_like_grades() -> None:
    args = commands()["sweep"].parse_args(
        ["--scenario", "approach_wall", "--scenario", "out_of_range,drive_past_10m"]
    )
    names, *_ = sweep._levels(args, {})
    assert names == ["approach_wall", "out_of_range", "drive_past_10m"]


def test_sim_refuses_an_animation_it_cannot_write_before_the_session(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The help promises FILE.gif (or .mp4): another suffix exits 2 now, not after the drive."""
    assert main(["sim", "--animation", "view.png", "--foxglove-port", "off"]) == 2
    assert "--animation view.png: an animation is written as .gif" in capsys.readouterr().err


@pytest.mark.parametrize(
    "counted, shown",
    [("not all passed", "3 not all passed"), ("did not finish", "3 did not finish")],
)
def test_the_cluster_progress_says_what_its_count_counts(counted: str, shown: str) -> None:
    """grade's count is of students with a scenario not passed, not of crashed tasks: each
    command names it (task_progress has no default wording)."""
    from harness.cluster.progress import add_task, task_progress

    out = io.StringIO()
    console = Console(file=out, width=200)
    progress = task_progress(console, "students", failed=counted)
    task = add_task(progress, "students", 10)
    progress.update(task, advance=4, running=2, failed=3)
    console.print(progress.make_tasks_table(progress.tasks))
    text = out.getvalue()
    assert f"2 running, {shown}" in text and " failed" not in text
    with pytest.raises(TypeError):
        task_progress(Console(file=io.StringIO()), "runs")  # type: ignore[call-arg]
