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

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fuzzyctl.runtime.config import Config, ConfigError, load_config, parse_config
    from fuzzyctl.runtime.core import Runtime

__all__ = ["Config", "ConfigError", "Runtime", "load_config", "parse_config"]


def __getattr__(name: str) -> Any:
    # Imported on first use: the API process (:mod:`.apiserver`) imports this package for
    # its HTTP side only, and must not load the blocks, the engine and the protocols.
    if name == "Runtime":
        from fuzzyctl.runtime.core import Runtime

        return Runtime
    if name in ("Config", "ConfigError", "load_config", "parse_config"):
        from fuzzyctl.runtime import config

        return getattr(config, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
