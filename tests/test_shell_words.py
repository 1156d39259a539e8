"""`~` and `$VAR` in paths and command lines, expanded as a shell would (harness.shell_words),
and through the command line's options: what a quoted ``--node "python3 ~/lab07/node.py"``
means, an unset variable as one usage line."""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from harness.cli import build_parser, main
from harness.commands.arguments import expand_arguments
from harness.shell_words import NotExpanded, _words, expand_command, expand_path

ENV = {"HOME": "/home/ana lee", "LAB": "/srv/lab07", "EMPTY": ""}


@pytest.mark.parametrize(
    ("command", "words"),
    [
        (
            "python3 ~/lab07/fossbot_lidar_node.py",
            ["python3", "/home/ana lee/lab07/fossbot_lidar_node.py"],
        ),
        ("python3 $LAB/node.py --x", ["python3", "/srv/lab07/node.py", "--x"]),
        ('python3 "${LAB}/my node.py"', ["python3", "/srv/lab07/my node.py"]),
        ("~/bin/agent --device {port}", ["/home/ana lee/bin/agent", "--device", "{port}"]),
        ("python3 n.py $EMPTY x", ["python3", "n.py", "x"]),  # an empty $VAR alone: no word
        ('python3 n.py "$EMPTY"', ["python3", "n.py", ""]),  # quoted: an empty word
        ("python3 '$LAB/~/n.py'", ["python3", "$LAB/~/n.py"]),  # single quotes: as written
        ('python3 \\$LAB "\\$LAB"', ["python3", "$LAB", "\\$LAB"]),  # escaped (as shlex reads)
        ('python3 "~/n.py" a~/b', ["python3", "~/n.py", "a~/b"]),  # ~ only unquoted, at the start
        ("echo $ a$ $%", ["echo", "$", "a$", "$%"]),  # a $ before nothing to expand stays
    ],
)
def test_commands_expand_as_a_shell_would(command: str, words: list[str]) -> None:
    """The words `shlex.split` reads from the result are those a shell would pass."""
    assert shlex.split(expand_command(command, ENV)) == words


def test_a_command_with_nothing_to_expand_is_unchanged() -> None:
    """What the run shows is what the user typed, unless something was expanded."""
    for command in ('python3  "my node.py"', "python3 'a b'", "python3 'open"):
        assert expand_command(command, ENV) == command


@pytest.mark.parametrize(
    ("path", "expanded"),
    [
        ("~/grades", "/home/ana lee/grades"),
        ("~", "/home/ana lee"),
        ("$LAB/out", "/srv/lab07/out"),
        ("${LAB}_v2/report", "/srv/lab07_v2/report"),
        ("report/~/x", "report/~/x"),
        ("cost$", "cost$"),
        ("approach_wall", "approach_wall"),
    ],
)
def test_paths_expand_a_leading_tilde_and_variables(path: str, expanded: str) -> None:
    assert expand_path(path, ENV) == expanded


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("$NOPE/x", "$NOPE is not set: set it (export NOPE=...), or write the value out"),
        ("${NOPE}", "$NOPE is not set"),
        ("$(pwd)/x", "$(...) is not run: the harness starts the command itself, without a shell"),
        ("`pwd`/x", "`...` is not run"),
        ("${LAB:-/tmp}", "${LAB:-/tmp}: only $NAME and ${NAME} are expanded: write the value out"),
        ("$1/x", "$1: only $NAME and ${NAME} are expanded"),
        ("${LAB", "${ without its closing }"),
        ("~no_such_user_here/x", "~no_such_user_here: no user 'no_such_user_here' on this machine"),
    ],
)
def test_what_only_a_shell_does_is_refused_with_the_fix(text: str, message: str) -> None:
    for expand in (expand_path, expand_command):
        with pytest.raises(NotExpanded) as raised:
            expand(text, ENV)
        assert str(raised.value).startswith(message)


@settings(max_examples=300, deadline=None)
@given(st.text(alphabet=st.sampled_from(list("ab ~$\\'\"/\t{}")), max_size=30))
def test_words_are_split_as_shlex_splits_them(text: str) -> None:
    """The expander reads the words (and their quoting) as the node's command is split."""
    try:
        expected = shlex.split(text)
    except ValueError:
        with pytest.raises(ValueError):
            _words(text)
        return
    assert ["".join(c for c, _ in word) for word, _ in _words(text)] == expected


def test_every_file_and_command_option_of_the_cli_is_expanded(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The command line's own parser, then the expansion `main` applies: each option that
    names a file or gives a command, positionals and repeated ones included."""
    for name, value in ENV.items():
        monkeypatch.setenv(name, value)
    run = build_parser().parse_args(
        ["run", "~/my.yaml", "approach_wall", "--node", "python3 ~/n.py", "--out", "$LAB/r"]
        + ["--junit-xml", "~/j.xml", "--workspace", "${LAB}/ws", "--baseline", "~/b.json"]
        + ["--board-command", "~/agent --device {port}", "--board-command", "$LAB/bridge"]
        + ["--processor", "~/f.py:process", "--grading", "~/g.yaml", "--gradescope", "~/r.json"]
    )
    expand_arguments(run)
    home = "/home/ana lee"
    assert run.scenarios == [f"{home}/my.yaml", "approach_wall"]
    assert run.node == f"python3 '{home}/n.py'"
    assert (run.out, run.junit_xml, run.workspace) == (
        "/srv/lab07/r",
        f"{home}/j.xml",
        "/srv/lab07/ws",
    )
    assert run.board_command == [f"'{home}/agent' --device {{port}}", "/srv/lab07/bridge"]
    assert (run.baseline, run.processor) == (f"{home}/b.json", f"{home}/f.py:process")
    assert (run.grading, run.gradescope) == (f"{home}/g.yaml", f"{home}/r.json")
    grade = build_parser().parse_args(
        ["grade", "~/class", "$LAB/mon", "--out", "~/grades", "--roster", "~/roster.csv"]
        + ["--scenario", "approach_wall,~/hidden.yaml"]
    )
    expand_arguments(grade)
    assert grade.dirs == [f"{home}/class", "/srv/lab07/mon"]
    assert (grade.out, grade.roster) == (f"{home}/grades", f"{home}/roster.csv")
    assert grade.scenario == [f"approach_wall,{home}/hidden.yaml"]
    for argv, field, value in (
        (
            ["sweep", "--scenario", "~/a.yaml,~/b.yaml"],
            "scenario",
            [[f"{home}/a.yaml", f"{home}/b.yaml"]],
        ),
        (["replay", "~/bag.mcap", "--record", "$LAB/r.mcap"], "recording", f"{home}/bag.mcap"),
        (["sim", "~/world.yaml", "--record", "$LAB/r.mcap"], "world", f"{home}/world.yaml"),
        (
            ["emulate", "rplidar", "--scenario", "~/s.yaml", "--port", "$LAB/tty"],
            "port",
            "/srv/lab07/tty",
        ),
    ):
        args = build_parser().parse_args(argv)
        expand_arguments(args)
        assert getattr(args, field) == value


@pytest.mark.parametrize(
    ("args", "line"),
    [
        (
            ["run", "--node", "python3 $LAB_DIR/node.py"],
            "--node 'python3 $LAB_DIR/node.py': $LAB_DIR is not set: set it (export "
            "LAB_DIR=...), or write the value out",
        ),
        (["run", "--out", "${OUT:-r}"], "--out '${OUT:-r}': ${OUT:-r}: only $NAME and ${NAME}"),
        (["run", "$SCENARIOS/a.yaml"], "SCENARIO '$SCENARIOS/a.yaml': $SCENARIOS is not set"),
        (["run", "--junit-xml", "$EMPTY"], "--junit-xml '$EMPTY': expands to nothing"),
        (
            ["run", "--link", "rplidar", "--board-command", "python3 $(pwd)/agent.py"],
            "--board-command 'python3 $(pwd)/agent.py': $(...) is not run",
        ),
        (["grade", "$CLASS"], "DIR '$CLASS': $CLASS is not set"),
        (["replay", "~no_such_user_here/bag"], "FILE '~no_such_user_here/bag': ~no_such_user_here"),
    ],
)
def test_an_unset_variable_is_one_usage_line(
    args: list[str], line: str, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Exit 2 and one line naming the option and the variable, before anything starts."""
    for name in ("LAB_DIR", "SCENARIOS", "CLASS"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("EMPTY", "")
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"fossbot-hil: error: {line}") and err.count("\n") == 1, err


def test_a_run_writes_where_its_expanded_paths_say(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--out '~/report'`, `--junit-xml '$RESULTS/junit.xml'` and a scenario file under `~`
    in a real (inprocess) run: the files are where a shell would have put them."""
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("RESULTS", str(tmp_path / "results"))
    monkeypatch.chdir(tmp_path)
    (tmp_path / "results").mkdir()
    shipped = Path(__file__).resolve().parents[1] / "harness" / "scenarios" / "out_of_range.yaml"
    (tmp_path / "mine.yaml").write_text(shipped.read_text())
    args = ["run", "~/mine.yaml", "--link", "inprocess", "--out", "~/report"]
    assert main([*args, "--junit-xml", "$RESULTS/junit.xml"]) == 0, capsys.readouterr()
    assert (tmp_path / "report" / "index.html").is_file()
    assert (tmp_path / "results" / "junit.xml").is_file()
    assert not (tmp_path / "~").exists()
