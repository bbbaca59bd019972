"""Request bodies of the studio API.  Every field is typed and bounded; unknown fields,
NaN and infinities are refused (422) before any handler runs."""

# No `from __future__ import annotations`: pydantic and FastAPI read these at run time.

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, StringConstraints

Name = Annotated[str, StringConstraints(min_length=1, max_length=200)]
RelPath = Annotated[str, StringConstraints(min_length=1, max_length=1000)]
Finite = Annotated[float, Field(allow_inf_nan=False)]


class Body(BaseModel):
    model_config = ConfigDict(extra="forbid")


class SurfaceSettings(Body):
    x: Name | None = None
    y: Name | None = None
    z: Name | None = None
    points: Annotated[int, Field(ge=5, le=80)] = 31
    fixed: dict[Name, Finite] = Field(default_factory=dict)


class Signal(Body):
    """A test signal of the curve recorder (Siemens 6.7)."""

    kind: Literal["constant", "minimum", "maximum", "zero", "triangle"] = "constant"
    value: Finite = 0.0
    min: Finite | None = None
    max: Finite | None = None
    periods: Annotated[float, Field(gt=0, le=1000, allow_inf_nan=False)] = 1.0
    duty: Annotated[float, Field(ge=0, le=100, allow_inf_nan=False)] = 50.0
    phase: Annotated[float, Field(ge=0, le=100, allow_inf_nan=False)] = 0.0


class RecorderSettings(Body):
    curves: Annotated[list[Name], Field(max_length=5)] = Field(default_factory=list)
    length: Annotated[float, Field(ge=10, le=9999, allow_inf_nan=False)] = 60.0
    archive: Annotated[float, Field(ge=10, le=9999, allow_inf_nan=False)] | None = Field(
        default=None, description="archive length in seconds: the display length to about three times it"
    )
    shared: bool | None = Field(default=None, description="curves of one quantity share one axis")
    bar_output: Name | None = None
    signals: dict[Name, Signal] = Field(default_factory=dict)
    loop: RelPath | None = None


class Settings(Body):
    """The studio's view settings, kept in the project's OPTIONS block."""

    ranges: dict[Name, Annotated[list[Finite], Field(min_length=2, max_length=2)]] = Field(
        default_factory=dict
    )
    surface: SurfaceSettings | None = None
    recorder: RecorderSettings | None = None


class ModelBody(Body):
    """A knowledge base in fuzzyctl's JSON form (docs/formats.md) and which function
    block of it is edited."""

    document: dict[str, Any]
    block: Annotated[int, Field(ge=0, le=100)] = 0
    settings: Settings = Field(default_factory=Settings)


class TextBody(Body):
    text: Annotated[str, StringConstraints(max_length=5_000_000)]


class PathBody(Body):
    path: RelPath


class SaveBody(ModelBody):
    path: RelPath
    expected_sha256: Annotated[str, StringConstraints(pattern=r"^[0-9a-f]{64}$")] | None = Field(
        default=None, description="the file's hash when it was opened; a different file on disk is a 409"
    )
    overwrite: bool = Field(default=False, description="Save As onto an existing file")


class SurfaceBody(ModelBody):
    x: Name
    y: Name
    z: Name
    fixed: dict[Name, Finite] = Field(default_factory=dict)
    points: Annotated[int, Field(ge=5, le=80)] = 31
    animate: Name | None = None
    step_percent: Annotated[float, Field(ge=1, le=50, allow_inf_nan=False)] = 10.0


class ExplainBody(ModelBody):
    inputs: dict[Name, Finite]


class RecordBody(ModelBody):
    signals: dict[Name, Signal] = Field(default_factory=dict)
    times: Annotated[list[Finite], Field(max_length=5000)]
    length: Annotated[float, Field(ge=10, le=9999, allow_inf_nan=False)] = 60.0
    reset: bool = False


class ImportBody(Body):
    filename: Name
    data_base64: Annotated[str, StringConstraints(max_length=10_000_000)]
    format: Name | None = None


class ExportBody(ModelBody):
    format: Name
    lossy: bool = False


class SimStartBody(ModelBody):
    config: RelPath
    parameters: dict[Name, Finite] = Field(default_factory=dict)
    setpoints: dict[Name, Finite] = Field(default_factory=dict)


class SimStepBody(Body):
    id: Annotated[str, StringConstraints(pattern=r"^[0-9a-f]{16}$")]
    seconds: Annotated[float, Field(gt=0, le=3600, allow_inf_nan=False)]


class OnlineBody(Body):
    url: Annotated[str, StringConstraints(min_length=1, max_length=500)]
    token: Annotated[str, StringConstraints(max_length=500)] | None = None
    instance: Name | None = None


class OnlineCommandBody(OnlineBody):
    action: Literal["start", "stop", "auto", "manual", "force", "release", "manual_value"]
    target: Name | None = Field(
        default=None, description="the input (force, release) or output (manual_value)"
    )
    value: Finite | None = None


class DownloadBody(OnlineBody, ModelBody):
    pass


class RulesTextBody(ModelBody):
    """The rule text editor: the lines of one rule block."""

    rule_block: Annotated[int, Field(ge=0, le=1000)] = 0
    text: Annotated[str, StringConstraints(max_length=5_000_000)]


class TermTextBody(ModelBody):
    """A term written as FCL (what follows ``:=``)."""

    variable: Name
    text: Annotated[str, StringConstraints(min_length=1, max_length=100_000)]


class RuleViewBody(ModelBody):
    """The rule viewer at one input point."""

    inputs: dict[Name, Finite]
