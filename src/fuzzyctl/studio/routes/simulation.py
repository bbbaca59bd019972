"""The simulated process: loop configurations of the project, and the simulations run
around the edited knowledge base (the logic is in :mod:`fuzzyctl.studio.simulate`)."""

# No `from __future__ import annotations`: FastAPI reads the annotations at run time.

from typing import Any

from fastapi import APIRouter
from fastapi.responses import JSONResponse

from fuzzyctl.jsonsafe import clean
from fuzzyctl.studio.routes.state import StudioDep, model_of
from fuzzyctl.studio.schemas import SimStartBody, SimStepBody
from fuzzyctl.studio.simulate import describe_configs

router = APIRouter()


@router.get("/api/sim/configs")
def sim_configs(studio: StudioDep, current: str | None = None) -> Any:
    """The loop configurations (TOML) in the project directory."""
    listing = [f["path"] for f in studio.project.listing()]
    return {"configs": clean(describe_configs(studio.project.root, listing, current))}


@router.post("/api/sim/start")
def sim_start(body: SimStartBody, studio: StudioDep) -> Any:
    """Build the loop of a configuration around the edited knowledge base."""
    path = studio.project.resolve(body.config, must_exist=True)
    _doc, fb = model_of(body)
    _sid, result = studio.sims.start(path, fb, parameters=body.parameters, setpoints=body.setpoints)
    return clean(result)


@router.post("/api/sim/step")
def sim_step(body: SimStepBody, studio: StudioDep) -> Any:
    """Run the next ``seconds`` of a loop; the rows recorded."""
    try:
        return studio.sims.step(body.id, body.seconds)
    except KeyError:
        return JSONResponse({"detail": "no such simulation (it was stopped or replaced)"}, status_code=404)


@router.delete("/api/sim/{sid}")
def sim_stop(sid: str, studio: StudioDep) -> dict[str, bool]:
    return {"stopped": studio.sims.stop(sid)}
