"""The front end: the page (which keeps the token of its URL in a cookie) and plotly.js
from the ``plotly`` package (offline, no CDN); ``/static`` is mounted by the app."""

# No `from __future__ import annotations`: FastAPI reads the annotations at run time.

import hashlib
from pathlib import Path

from fastapi import APIRouter, Request
from fastapi.responses import FileResponse, RedirectResponse, Response

from fuzzyctl.diagnostics import FuzzyctlError
from fuzzyctl.studio.routes.state import StudioDep

STATIC = Path(__file__).parent.parent / "static"
COOKIE_PREFIX = "fuzzyctl_studio_"

router = APIRouter(include_in_schema=False)


def cookie_name(token: str) -> str:
    """The cookie holding ``token``: named after a digest of it, because browsers share
    cookies between the ports of a host (a second studio must not log the first one out)."""
    return COOKIE_PREFIX + hashlib.sha256(token.encode()).hexdigest()[:16]


def plotly_bundle() -> Path:
    """plotly.js as shipped inside the ``plotly`` Python package (offline, no CDN)."""
    import plotly

    path = Path(plotly.__file__).parent / "package_data" / "plotly.min.js"
    if not path.is_file():
        raise FuzzyctlError(f"plotly.min.js not found in the plotly package ({path})")
    return path


@router.get("/vendor/plotly.min.js")
def plotly_file(studio: StudioDep) -> FileResponse:
    return FileResponse(
        studio.plotly_js, media_type="text/javascript", headers={"Cache-Control": "max-age=86400"}
    )


@router.get("/")
def index(request: Request, studio: StudioDep) -> Response:
    token = studio.token
    if token is not None and "token" in request.query_params:
        # The front door checked it: keep it in a cookie, and take it out of the address bar.
        from urllib.parse import urlencode

        rest = [(k, v) for k, v in request.query_params.multi_items() if k != "token"]
        target = "/" + ("?" + urlencode(rest) if rest else "")
        response = RedirectResponse(target, status_code=303)
        response.set_cookie(cookie_name(token), token, httponly=True, samesite="strict", path="/")
        return response
    return FileResponse(STATIC / "index.html", headers={"Cache-Control": "no-cache"})
