"""Field I/O connectors: OPC UA, Modbus TCP and Siemens S7.

Every connector speaks the small interface of :class:`fuzzyctl.io.base.Connector`
(connect, read a batch of points, write a batch of points, close, link state), so the
runtime treats them alike.  Values cross the interface as Python floats in engineering
units; each connector converts to and from its wire types (IEEE REAL/Float, FLOAT32 over
two registers in either word order, scaled INT16).

The protocol libraries are imported only by the module that needs them
(:mod:`fuzzyctl.io.opcua`, :mod:`fuzzyctl.io.modbus`, :mod:`fuzzyctl.io.s7`);
:func:`create_connector` picks the module from the connection ``type``.
"""

from fuzzyctl.io.base import Connector, LinkError, LinkState, Point, create_connector

__all__ = ["Connector", "LinkError", "LinkState", "Point", "create_connector"]
