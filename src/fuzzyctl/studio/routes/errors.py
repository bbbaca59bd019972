"""How the studio answers an exception: a status and a message the user can act on, never
a traceback (the module docstring of :mod:`fuzzyctl.studio.app` lists the statuses)."""

# No `from __future__ import annotations`: FastAPI reads the annotations at run time.

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse

from fuzzyctl.diagnostics import DiagnosticError, FuzzyctlError
from fuzzyctl.files import ReadOnlyError
from fuzzyctl.jsonsafe import clean
from fuzzyctl.studio import online
from fuzzyctl.studio.project import FileProblem, PathError, os_problem


def add_handlers(app: FastAPI) -> None:
    """Install the exception handlers on ``app`` (whose ``state.studio`` names files)."""

    @app.exception_handler(RequestValidationError)
    async def _invalid(_request: Request, exc: RequestValidationError) -> JSONResponse:
        # The field and the reason, never the value sent (which may be megabytes).
        errors = [
            {
                "type": e.get("type"),
                "loc": [str(x)[:64] for x in e.get("loc", ())],
                "msg": str(e.get("msg"))[:200],
            }
            for e in exc.errors()[:20]
        ]
        return JSONResponse({"detail": errors}, status_code=422)

    @app.exception_handler(PathError)
    async def _path_error(_request: Request, exc: PathError) -> JSONResponse:
        return JSONResponse({"detail": str(exc)}, status_code=403)

    @app.exception_handler(FileProblem)
    async def _file_problem(_request: Request, exc: FileProblem) -> JSONResponse:
        return JSONResponse({"detail": str(exc)}, status_code=exc.status)

    @app.exception_handler(ReadOnlyError)
    async def _read_only(request: Request, exc: ReadOnlyError) -> JSONResponse:
        name = request.app.state.studio.project.relative(exc.path)
        return JSONResponse(
            {
                "detail": f"{name} is read-only: not saved (make it writable, or save under another name)",
                "readonly": True,
            },
            status_code=403,
        )

    @app.exception_handler(OSError)
    async def _os_error(request: Request, exc: OSError) -> JSONResponse:
        # The routes that touch files say which file; this is the net under the others.
        problem = os_problem(exc, request.url.path, "answer")
        return JSONResponse({"detail": str(problem)}, status_code=problem.status)

    @app.exception_handler(online.OnlineError)
    async def _online_error(_request: Request, exc: online.OnlineError) -> JSONResponse:
        return JSONResponse(
            {"detail": str(exc), "status": exc.status, "runtime": clean(exc.body)}, status_code=502
        )

    @app.exception_handler(DiagnosticError)
    async def _diagnostics(_request: Request, exc: DiagnosticError) -> JSONResponse:
        return JSONResponse(
            {"detail": exc.render(), "diagnostics": [d.to_dict() for d in exc.diagnostics]}, status_code=422
        )

    @app.exception_handler(FuzzyctlError)
    async def _error(_request: Request, exc: FuzzyctlError) -> JSONResponse:
        return JSONResponse({"detail": str(exc)}, status_code=422)
