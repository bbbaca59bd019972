"""The project's files: what the studio knows, listing, opening, saving, and import and
export in every format of the registry (:mod:`fuzzyctl.formats`)."""

# No `from __future__ import annotations`: FastAPI reads the annotations at run time.

import base64
import binascii
from pathlib import Path
from typing import Any

from fastapi import APIRouter
from fastapi.responses import JSONResponse

from fuzzyctl import __version__, formats
from fuzzyctl.diagnostics import FuzzyctlError, InputError
from fuzzyctl.files import check_writable
from fuzzyctl.jsonsafe import clean
from fuzzyctl.studio import analysis, viewsettings
from fuzzyctl.studio.project import (
    MAX_FILE,
    FileProblem,
    PathError,
    ProjectDir,
    check_save_name,
    os_problem,
    save_atomically,
    sha256,
    split_settings,
)
from fuzzyctl.studio.routes.state import StudioDep, model_of, opened, settings_of
from fuzzyctl.studio.schemas import ExportBody, ImportBody, PathBody, SaveBody

router = APIRouter()


@router.get("/api/info")
def info(studio: StudioDep) -> dict[str, Any]:
    """Version, project directory, the file opened at start, formats, and the name limits
    of the S7 configuration tool its dialogs check (the siemens profile's)."""
    from fuzzyctl.blocks.siemens.profile import LIMITS

    return {
        "version": __version__,
        "root": str(studio.project.root),
        "file": studio.file,
        "siemens_limits": {k: LIMITS[k] for k in ("project_name", "variable_name", "term_name")},
        "formats": [
            {
                "name": f.name,
                "extensions": list(f.extensions),
                "read": f.read is not None,
                "write": f.write is not None,
                "description": f.description,
            }
            for f in formats.available()
        ],
    }


@router.get("/api/files")
def files(studio: StudioDep) -> dict[str, Any]:
    """The files of the project directory the studio can open."""
    return {"root": str(studio.project.root), "files": studio.project.listing()}


@router.post("/api/open")
def open_file(body: PathBody, studio: StudioDep) -> Any:
    """Read a project file (FCL), or import another format (it then has no path until
    it is saved as FCL)."""
    path = studio.project.resolve(body.path, must_exist=True)
    try:
        size = path.stat().st_size
        if size > MAX_FILE:
            raise FileProblem(
                413,
                f"{body.path} is too big: {size / 2**20:.1f} MB, the studio opens files of up to "
                f"{MAX_FILE // 2**20} MB",
            )
        data = path.read_bytes()
    except OSError as exc:
        raise os_problem(exc, body.path, "open") from None
    return clean(opened(studio.project, path, formats.decode(data)))


@router.post("/api/save")
def save(body: SaveBody, studio: StudioDep) -> Any:
    """Write the model as FCL, atomically; the view settings go to a sidecar
    (studio/viewsettings.py), never into the file.  Refused when the file changed on
    disk since it was opened."""
    project = studio.project
    if not body.path.lower().endswith(".fcl"):
        raise PathError("projects are FCL files: the name must end in .fcl")
    check_save_name(body.path)
    path = project.resolve(body.path)
    check_save_name(project.relative(path))  # a symbolic link into .git/ is refused too
    document, _fb = model_of(body)
    text = analysis.fcl_text(document)  # the user's file only: view settings beside it
    try:
        result = _saved(project, body, path, text)
    except OSError as exc:
        raise os_problem(exc, body.path, "save") from None
    if isinstance(result, dict):
        viewsettings.write_settings(project.root, project.relative(path), settings_of(body))
    return result


def _saved(project: ProjectDir, body: SaveBody, path: Path, text: str) -> Any:
    check_writable(path)  # told at once, not after "Replace it?"
    if path.exists():
        current = sha256(path.read_text(encoding="utf-8", errors="replace"))
        if body.expected_sha256 is None and not body.overwrite:
            return JSONResponse({"detail": f"{body.path} exists", "exists": True}, status_code=409)
        if body.expected_sha256 is not None and body.expected_sha256 != current and not body.overwrite:
            return JSONResponse(
                {"detail": f"{body.path} was changed on disk since it was opened", "changed": True},
                status_code=409,
            )
    save_atomically(path, text)
    report = analysis.check_text(text, body.path)
    return {"path": project.relative(path), "sha256": sha256(text), "text": text, **report.to_dict()}


@router.post("/api/import")
def import_file(body: ImportBody) -> Any:
    """Read an uploaded file in any format ``fuzzyctl convert`` knows."""
    try:
        data = base64.b64decode(body.data_base64, validate=True)
    except (binascii.Error, ValueError):
        raise InputError("data_base64 is not base64") from None
    fmt = formats.get(body.format) if body.format else formats.for_path(body.filename)
    loaded = formats.read_text(formats.decode(data), fmt.name, path=body.filename)
    document, settings = split_settings(loaded.document)
    text = analysis.fcl_text(document)
    report = analysis.check_text(text)
    return clean(
        {
            "format": fmt.name,
            "document": analysis.document_to_json(document),
            "settings": settings,
            "text": text,
            **analysis.views(document, settings),
            "warnings": [d.to_dict() for d in loaded.diagnostics],
            **report.to_dict(),
        }
    )


@router.post("/api/export")
def export(body: ExportBody) -> Any:
    """The model in another format.  Without ``lossy`` a format that cannot express
    everything answers ``losses`` and no text, so the browser can ask first."""
    document, _fb = model_of(body)
    fmt = formats.get(body.format)
    if fmt.write is None:
        raise FuzzyctlError(f"format {fmt.name!r} can be read but not written")
    losses = [str(loss) for loss in fmt.losses(document)]
    if losses and not body.lossy:
        return {"format": fmt.name, "losses": losses, "text": None}
    text, _ = formats.convert(document, fmt.name, lossy=True)
    name = (document.main.name or "project") + fmt.extensions[0]
    return {"format": fmt.name, "losses": losses, "text": text, "filename": name}
