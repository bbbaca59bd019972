"""Closed-loop simulation: plant models, the controller structures of IEC 61131-7 (Annex A.3
and B) around a fuzzy function block, a PID block, and quality figures.

>>> import fuzzyctl
>>> from fuzzyctl import sim
>>> plant = sim.make_plant("crane", {"load_mass": 20000})
>>> fuzzy = sim.make_runtime(fuzzyctl.load("examples/crane.fcl"))
>>> structure = sim.DirectFuzzy(fuzzy, {"distance": "target - position", "angle": "angle"})
>>> loop = sim.Loop(plant, structure, period=0.05, setpoints={"target": sim.profiles.constant(20)})
>>> row = loop.step()            # one controller cycle (a studio steps like this)
>>> trace = loop.run(60)         # or the rest in one go
>>> q = sim.quality(trace, "load_position", "target", band=0.1, limits={"angle": 2})

See docs/sim.md.
"""

from fuzzyctl.sim import profiles
from fuzzyctl.sim.integrate import Adaptive, FixedStep, make_integrator
from fuzzyctl.sim.loop import Loop, Trace
from fuzzyctl.sim.metrics import Quality, quality
from fuzzyctl.sim.pid import PID
from fuzzyctl.sim.plant import PLANTS, OdePlant, Plant, Port, make_plant
from fuzzyctl.sim.runtimes import RUNTIMES, EngineRuntime, FuzzyRuntime, make_runtime
from fuzzyctl.sim.signals import Expression
from fuzzyctl.sim.structures import DirectFuzzy, FuzzyPI, GainScheduledPID, PIDLoop, PreControl, Structure

__all__ = [
    "PID",
    "PLANTS",
    "RUNTIMES",
    "Adaptive",
    "DirectFuzzy",
    "EngineRuntime",
    "Expression",
    "FixedStep",
    "FuzzyPI",
    "FuzzyRuntime",
    "GainScheduledPID",
    "Loop",
    "OdePlant",
    "PIDLoop",
    "Plant",
    "Port",
    "PreControl",
    "Quality",
    "Structure",
    "Trace",
    "make_integrator",
    "make_plant",
    "make_runtime",
    "profiles",
    "quality",
]
