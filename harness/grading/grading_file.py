"""The instructor's grading file (e.g. grading.yaml): scenarios, weights, hidden ones, judging.

```yaml
scenarios:
  - approach_wall                   # a shipped scenario, weight 1
  - scenario: out_of_range
    weight: 2
  - scenario: hidden/narrow_corridor.yaml   # a file, relative to this grading file
    weight: 3
    hidden: true                    # students see "hidden 1" and whether it passed
    show_failure: false             # ... and its first failure only if true
points: 100                         # what a full pass earns (default: the sum of the weights)
partial_credit: false               # true: a failed scenario earns its share of ticks held
threshold: 0.5                      # the judging options, as on the command line
timeout: 1.0
gradebook:                          # gradebook.csv, for the LMS's import
  column: Lab 07                    # the assignment's title in the LMS
  ids: SIS User ID                  # where the roster's ids go (or SIS Login ID)
```

Read with the scenarios' own bounded YAML loader and validated here (pure:
no rclpy, no pybullet). Paths (`~` and `$VAR` expanded as a shell would) are
made absolute against the file's folder now, so nothing is ever resolved
inside a student's folder.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import yaml
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    create_model,
    field_validator,
)

from harness.errors import ConfigError
from harness.option_names import named
from harness.run_request import OPTIONS, OptionError, RunOption
from harness.run_request.table import names
from harness.scenario.files import SCENARIO_SUFFIXES
from harness.scenario.yaml_loader import load_yaml, yaml_problem
from harness.text_file import read_text_file

if TYPE_CHECKING:
    from harness.grading.scoring import ScorePlan

__all__ = ["GradebookSettings", "GradingFile", "PlannedScenario", "load_grading_file"]

MAX_GRADING_FILE_BYTES = 1 << 20


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class PlannedScenario(_Strict):
    """One scenario of the grading file."""

    scenario: str = Field(min_length=1, max_length=1000)  # a shipped name or a file
    weight: float = Field(default=1.0, ge=0.0, le=1e6)
    hidden: bool = False
    show_failure: bool = False  # hidden only: students see its first failure
    label: str | None = Field(default=None, min_length=1, max_length=80)


class GradebookSettings(_Strict):
    """gradebook.csv's assignment column and the column the roster's ids go in."""

    column: str = Field(default="Lab 07", min_length=1, max_length=200)
    ids: Literal["SIS User ID", "SIS Login ID"] = "SIS User ID"

    @field_validator("column")
    @classmethod
    def _an_lms_title(cls, value: str) -> str:
        from harness.grading.gradebook import check_column

        try:
            return check_column(value)
        except ConfigError as error:
            raise ValueError(str(error)) from None


#: The run options a grading file may set, by field name: the run request's table's rows
#: with a grading-file field (a new one there is a new field here).
RUN_FIELDS: dict[str, RunOption] = {row.grading: row for row in OPTIONS if row.grading}
_RunOptions = create_model(  # type: ignore[call-overload]
    "_RunOptions", __base__=_Strict, **{name: (Any, None) for name in RUN_FIELDS}
)


class GradingFile(_RunOptions):  # type: ignore[valid-type, misc]
    """What grade and run take from the grading file; None leaves an option as given."""

    scenarios: list[PlannedScenario] = Field(min_length=1, max_length=500)
    points: float | None = Field(default=None, gt=0.0, le=1e6)
    partial_credit: bool = False
    gradebook: GradebookSettings = GradebookSettings()
    source: str = Field(default="", exclude=True)

    @field_validator(*RUN_FIELDS)
    @classmethod
    def _a_run_option(cls, value: Any, info: ValidationInfo) -> Any:
        """Each run option read by its row, as the command line's is; a problem names the
        field ("seed must be a whole number ...")."""
        if value is None:
            return None
        name = info.field_name or ""
        row = RUN_FIELDS[name]
        if row.number and isinstance(value, str):
            raise ValueError(f"{name} must be a number, got {value[:40]!r}")
        texts = [value] if isinstance(value, str) else value
        if row.key == "faults" and not (
            isinstance(texts, list) and all(isinstance(f, str) for f in texts)
        ):
            raise ValueError("faults: give a profile name, 'a,b' or a list of names")
        try:
            return row.value(value)
        except OptionError as err:
            raise ValueError(err.render(names("grading"), subject=True)) from None

    @field_validator("scenarios", mode="before")
    @classmethod
    def _names_are_entries(cls, value: Any) -> Any:
        """`- approach_wall` is short for `- scenario: approach_wall`."""
        if isinstance(value, list):
            return [{"scenario": e} if isinstance(e, str) else e for e in value]
        return value

    @field_validator("scenarios")
    @classmethod
    def _some_weight(cls, value: list[PlannedScenario]) -> list[PlannedScenario]:
        if not any(e.weight > 0 for e in value):
            raise ValueError("every scenario has weight 0: nothing can be scored")
        return value

    @property
    def planned(self) -> tuple[PlannedScenario, ...]:
        """The entries, hidden ones labelled "hidden N" unless the file names them."""
        planned, hidden = [], 0
        for e in self.scenarios:
            if e.hidden:
                hidden += 1
                e = e.model_copy(update={"label": e.label or f"hidden {hidden}"})
            planned.append(e)
        return tuple(planned)

    def score_plan(self, names: Sequence[str]) -> ScorePlan:
        """How the scenarios score, `names` being what each entry resolved to, in order."""
        from harness.grading.scoring import ScenarioScore, ScorePlan

        return ScorePlan(
            tuple(
                ScenarioScore(name, p.weight, p.hidden, p.show_failure, p.label or "")
                for name, p in zip(names, self.planned, strict=True)
            ),
            points=self.points,
            partial_credit=self.partial_credit,
        )

    def request_values(self) -> dict[str, Any]:
        """The run options the file sets, by the run request's keys (faults as a list)."""
        return {
            row.key: getattr(self, name)
            for name, row in RUN_FIELDS.items()
            if getattr(self, name) is not None
        }


def _expanded(ref: str, where: str) -> str:
    """A scenario file's `~` and `$VAR` expanded as a shell would (no shell reads this
    file); ConfigError naming `where` for an unset variable."""
    from harness.shell_words import NotExpanded, expand_path

    try:
        return expand_path(ref)
    except NotExpanded as err:
        raise ConfigError(f"{where} {ref!r}: {err}") from None


def _absolute(ref: str, folder: Path) -> str:
    """A scenario file named by the grading file, as an absolute path; a name stays a name."""
    candidate = Path(ref)
    if candidate.suffix in SCENARIO_SUFFIXES or "/" in ref or (folder / ref).exists():
        return str((folder / candidate).resolve())
    return ref


def load_grading_file(path: str | Path) -> GradingFile:
    """The grading file at `path`, validated, its scenario files made absolute; ConfigError
    (exit 2) naming the file and the first problem."""
    path = Path(path)
    name = f"{named('grading')} {path}"
    text = read_text_file(path, limit=MAX_GRADING_FILE_BYTES, name=name, kind="grading file")
    try:
        raw = load_yaml(text)
    except yaml.YAMLError as err:
        raise ConfigError(f"{name}: {yaml_problem(err)}") from None
    except (RecursionError, ValueError) as err:
        raise ConfigError(f"{name}: YAML error: {err}") from None
    if not isinstance(raw, dict):
        raise ConfigError(f"{name}: expected a mapping with a 'scenarios' list")
    try:
        parsed = GradingFile.model_validate(raw)
    except ValidationError as err:
        raise ConfigError(f"{name}: {_first_error(err)}") from None
    folder = path.resolve().parent
    scenarios = []
    for i, e in enumerate(parsed.scenarios):
        ref = _expanded(e.scenario, f"{name}: scenarios.{i}.scenario")
        scenarios.append(e.model_copy(update={"scenario": _absolute(ref, folder)}))
    return parsed.model_copy(update={"scenarios": scenarios, "source": str(path)})


def _first_error(err: ValidationError) -> str:
    first = err.errors()[0]
    where = ".".join(str(p) for p in first["loc"])
    message = str(first["msg"]).removeprefix("Value error, ")
    if not where or message.startswith(f"{where} ") or message.startswith(f"{where}:"):
        return message or where  # the message names the field itself
    return f"{where}: {message}"
