"""The plant models; importing this package registers them (``fuzzyctl.sim.plant.PLANTS``)."""

from fuzzyctl.sim.plants.crane import Crane
from fuzzyctl.sim.plants.fmu import FmuPlant
from fuzzyctl.sim.plants.fopdt import Fopdt
from fuzzyctl.sim.plants.pendulum import InvertedPendulum
from fuzzyctl.sim.plants.tank import HeatedTank

__all__ = ["Crane", "FmuPlant", "Fopdt", "HeatedTank", "InvertedPendulum"]
