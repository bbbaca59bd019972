"""The soft controller behind ``fuzzyctl serve``: fuzzy function blocks (Siemens FUZZY,
Schneider XFUZ) running cyclically against field I/O (OPC UA, Modbus TCP, S7).

* :mod:`.config` reads and checks the TOML configuration;
* :mod:`.kb` and :mod:`.adapters` load knowledge bases and drive the two block styles;
* :mod:`.instance` is one block with its bindings, safety logic and online download;
* :mod:`.links` keeps the process image in step with the field, :mod:`.scheduler` runs
  the cycles, :mod:`.events` records what happens;
* :mod:`.core` puts them together (:class:`Runtime`), :mod:`.api` serves HTTP and
  WebSocket, :mod:`.display` draws the live table.

docs/runtime.md is the reference.
"""

from fuzzyctl.runtime.config import Config, ConfigError, load_config, parse_config
from fuzzyctl.runtime.core import Runtime

__all__ = ["Config", "ConfigError", "Runtime", "load_config", "parse_config"]
