"""On line: a running ``fuzzyctl serve`` - its instances, live values, commands, and the
download of the edited knowledge base (the HTTP client is :mod:`fuzzyctl.studio.online`)."""

# No `from __future__ import annotations`: FastAPI reads the annotations at run time.

from typing import Any

from fastapi import APIRouter

from fuzzyctl.diagnostics import InputError
from fuzzyctl.model import Document
from fuzzyctl.studio import analysis, online
from fuzzyctl.studio.routes.state import model_of
from fuzzyctl.studio.schemas import DownloadBody, OnlineBody, OnlineCommandBody

router = APIRouter()


@router.post("/api/online/instances")
def online_instances(body: OnlineBody) -> Any:
    """Connect: the runtime's health and instances."""
    health = online.call(body.url, "GET", "/health")
    instances = online.call(body.url, "GET", "/instances", token=body.token)
    return {"health": health, "instances": instances, "api": online.base_url(body.url)}


@router.post("/api/online/read")
def online_read(body: OnlineBody) -> Any:
    """Live values of the chosen instance."""
    if not body.instance:
        raise InputError("choose an instance")
    return online.call(body.url, "GET", f"/instances/{online.quote(body.instance)}", token=body.token)


@router.post("/api/online/command")
def online_command(body: OnlineCommandBody) -> Any:
    """START_STOP, MAN_AUTO, forcing and manual values (need the token)."""
    if not body.instance:
        raise InputError("choose an instance")
    base = f"/instances/{online.quote(body.instance)}"
    tok = body.token
    if body.action in ("start", "stop"):
        return online.call(
            body.url, "PUT", f"{base}/start_stop", token=tok, body={"running": body.action == "start"}
        )
    if body.action in ("auto", "manual"):
        return online.call(body.url, "PUT", f"{base}/mode", token=tok, body={"mode": body.action})
    if not body.target:
        raise InputError(f"{body.action}: name the input or output")
    target = online.quote(body.target)
    if body.action == "release":
        return online.call(body.url, "DELETE", f"{base}/force/{target}", token=tok)
    if body.value is None:
        raise InputError(f"{body.action}: give a value")
    where = "force" if body.action == "force" else "manual"
    return online.call(body.url, "PUT", f"{base}/{where}/{target}", token=tok, body={"value": body.value})


@router.post("/api/online/diff")
def online_diff(body: DownloadBody) -> Any:
    """The running knowledge base and the edited one, both as FCL (the confirm
    dialog of a download shows their difference)."""
    if not body.instance:
        raise InputError("choose an instance")
    running = online.knowledge_base_fcl(body.url, body.instance, token=body.token)
    _document, fb = model_of(body)
    return {"running": running, "edited": analysis.fcl_text(Document((fb,)))}


@router.post("/api/online/download")
def online_download(body: DownloadBody) -> Any:
    """Send the edited knowledge base (FCL, without the studio's settings)."""
    if not body.instance:
        raise InputError("choose an instance")
    _document, fb = model_of(body)
    text = analysis.fcl_text(Document((fb,)))
    return online.call(
        body.url,
        "PUT",
        f"/instances/{online.quote(body.instance)}/knowledge_base",
        token=body.token,
        body={"text": text, "format": "fcl"},
    )
