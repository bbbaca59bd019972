"""What the studio's routers share: one :class:`Studio` per app (on ``app.state``), and the
helpers that turn a request's model into the engine's."""

# No `from __future__ import annotations`: FastAPI reads the annotations at run time.

from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any

from fastapi import Depends, Request

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.model import Document, FunctionBlock
from fuzzyctl.studio import analysis, viewsettings
from fuzzyctl.studio.project import ProjectDir, sha256, split_settings
from fuzzyctl.studio.schemas import ModelBody
from fuzzyctl.studio.simulate import SimSessions


@dataclass
class Studio:
    """The state of one studio: its project directory, the file opened at start, the
    token (None: served without one), the compiled controllers and the simulations."""

    project: ProjectDir
    file: str | None
    token: str | None
    plotly_js: Path
    cache: analysis.ControllerCache = field(default_factory=analysis.ControllerCache)
    sims: SimSessions = field(default_factory=SimSessions)


def studio_of(request: Request) -> Studio:
    """The studio serving ``request`` (set by :func:`fuzzyctl.studio.app.create_app`)."""
    state: Studio = request.app.state.studio
    return state


StudioDep = Annotated[Studio, Depends(studio_of)]


def model_of(body: ModelBody, *, validated: bool = True) -> tuple[Document, FunctionBlock]:
    """The request's document and the function block it names."""
    document, _settings = split_settings(analysis.document_from_json(body.document, validated=validated))
    if not document.blocks:
        raise FuzzyctlError("the model has no function block")
    if body.block >= len(document.blocks):
        raise FuzzyctlError(f"block {body.block}: the model has {len(document.blocks)} function block(s)")
    return document, document.blocks[body.block]


def settings_of(body: ModelBody) -> dict[str, Any]:
    """The request's view settings, as the analysis functions take them."""
    return body.settings.model_dump(exclude_none=True)


def opened(project: ProjectDir, path: Path, text: str) -> dict[str, Any]:
    """What the browser gets for a file: the model, the settings, the check report."""
    from fuzzyctl.formats import read_text

    rel = project.relative(path)
    suffix = path.suffix.lower()
    if suffix == ".fcl":
        report = analysis.check_text(text, rel)
        if report.document is None:
            return {
                "path": rel,
                "text": text,
                "sha256": sha256(text),
                "document": None,
                **report.to_dict(),
            }
        document, settings = split_settings(report.document)
        settings = viewsettings.merged(project.root, rel, settings)
    else:
        document, settings = split_settings(read_text(text, suffix.lstrip("."), path=rel).document)
        report = analysis.check_text(analysis.fcl_text(document), rel)
        return {
            "path": None,
            "imported_from": rel,
            "text": analysis.fcl_text(document),
            "sha256": None,
            "document": analysis.document_to_json(document),
            "settings": settings,
            **analysis.views(document, settings),
            **report.to_dict(),
        }
    return {
        "path": rel,
        "text": text,
        "sha256": sha256(text),
        "document": analysis.document_to_json(document),
        "settings": settings,
        **analysis.views(document, settings),
        **report.to_dict(),
    }
