"""OPC UA (asyncua): a client that reads and writes nodes of a remote server, and a server
that exposes the runtime's instances as nodes under its own namespace.

Values are Float (IEEE single, the S7 REAL) unless a point says otherwise; integer types
are written rounded to the nearest (halves away from zero) and saturated to their range.
"""

from __future__ import annotations

import contextlib
import logging
import math
from collections.abc import Sequence
from typing import Any, Literal
from urllib.parse import urlsplit, urlunsplit

from pydantic import BaseModel, ConfigDict, Field

from fuzzyctl.io.base import Connector, LinkError, Point, bounded

__all__ = ["OpcUaClient", "OpcUaClientOptions", "OpcUaPoint", "OpcUaServer", "OpcUaServerOptions"]

# asyncua logs every failed request and every connection warning; the runtime reports link
# state itself (and asyncua warns about the absence of encryption on each connect).
logging.getLogger("asyncua").setLevel(logging.CRITICAL)

VariantName = Literal["Float", "Double", "Boolean", "Byte", "SByte", "Int16", "UInt16", "Int32", "UInt32"]
_INT_RANGES = {
    "Byte": (0, 255),
    "SByte": (-128, 127),
    "Int16": (-32768, 32767),
    "UInt16": (0, 65535),
    "Int32": (-(2**31), 2**31 - 1),
    "UInt32": (0, 2**32 - 1),
}


def to_variant(value: float, type_name: str) -> Any:
    """A float as an asyncua ``DataValue`` of the given variant type."""
    from asyncua import ua

    vtype = getattr(ua.VariantType, type_name)
    v: float | int | bool
    if type_name in ("Float", "Double"):
        v = float(value)
    elif type_name == "Boolean":
        v = bool(value) and not math.isnan(value)
    else:
        if math.isnan(value):
            raise ValueError(f"NaN cannot be written as {type_name}")
        low, high = _INT_RANGES[type_name]
        n = math.floor(abs(value) + 0.5) * (1 if value >= 0 else -1) if math.isfinite(value) else value
        v = int(min(max(n, low), high))
    return ua.DataValue(ua.Variant(v, vtype))


def from_value(value: Any) -> float:
    """A read node value as a float (booleans 0/1; anything else non-numeric is NaN)."""
    if isinstance(value, bool | int | float):
        return float(value)
    return math.nan


class OpcUaPoint(Point):
    """A node: ``{node = "ns=2;s=Tank.Level"}``; with ``namespace = "urn:..."`` the index
    is looked up on the server (``node = "s=Tank.Level"``)."""

    node: str = Field(min_length=1)
    namespace: str | None = None
    type: VariantName = "Float"

    def describe(self) -> str:
        return f"{self.node} ({self.type})" if self.namespace is None else f"{self.namespace}:{self.node}"


class OpcUaClientOptions(BaseModel):
    model_config = ConfigDict(extra="forbid")

    url: str = Field(pattern=r"^opc\.tcp://", description="endpoint, e.g. opc.tcp://plc:4840")
    timeout: float = Field(default=2.0, gt=0, le=60)
    username: str | None = None
    password: str | None = None


class OpcUaClient(Connector):
    """An OPC UA client session (security mode None, optional user name)."""

    point_model = OpcUaPoint
    options_model = OpcUaClientOptions
    options: OpcUaClientOptions

    def __init__(self, name: str, options: OpcUaClientOptions) -> None:
        super().__init__(name, options)
        self._client: Any = None
        self._nodes: dict[OpcUaPoint, Any] = {}

    def endpoint(self) -> str:
        return self.options.url

    async def connect(self) -> None:
        from asyncua.client.client import Client

        await self.close()
        o = self.options
        client = Client(o.url, timeout=o.timeout)
        if o.username is not None:
            client.set_user(o.username)
        if o.password is not None:
            client.set_password(o.password)
        try:
            await bounded(client.connect(), o.timeout * 2, "connect")
        # asyncua raises OSError, TimeoutError, its own UaError and ua status exceptions
        except Exception as exc:
            await _disconnect(client)
            raise LinkError(f"{o.url}: {exc or type(exc).__name__}") from exc
        self._client = client
        self._nodes = {}

    async def _resolve(self, points: Sequence[OpcUaPoint]) -> list[Any]:
        from asyncua import ua
        from asyncua.ua.uaerrors import UaError

        client = self._client
        out = []
        for p in points:
            node = self._nodes.get(p)
            if node is None:
                try:
                    if p.namespace is not None:
                        idx = await client.get_namespace_index(p.namespace)
                        node_id = ua.NodeId.from_string(f"ns={idx};{p.node}")
                    else:
                        node_id = ua.NodeId.from_string(p.node)
                except (ValueError, UaError) as exc:
                    raise LinkError(f"{self.options.url}: node {p.describe()}: {exc}") from exc
                node = self._nodes[p] = client.get_node(node_id)
            out.append(node)
        return out

    async def read(self, points: Sequence[Point]) -> list[float]:
        self.live(self._client)
        pts: list[OpcUaPoint] = list(points)  # type: ignore[arg-type]
        try:
            nodes = await self._resolve(pts)
            values = await bounded(self._client.read_values(nodes), self.options.timeout, "read")
        except LinkError:
            raise
        except Exception as exc:
            raise LinkError(f"{self.options.url}: read: {exc or type(exc).__name__}") from exc
        return [from_value(v) for v in values]

    async def write(self, points: Sequence[Point], values: Sequence[float]) -> None:
        self.live(self._client)
        pts: list[OpcUaPoint] = list(points)  # type: ignore[arg-type]
        try:
            nodes = await self._resolve(pts)
            data = [to_variant(v, p.type) for p, v in zip(pts, values, strict=True)]
            await bounded(self._client.write_values(nodes, data), self.options.timeout, "write")
        except LinkError:
            raise
        except Exception as exc:
            raise LinkError(f"{self.options.url}: write: {exc or type(exc).__name__}") from exc

    async def close(self) -> None:
        client, self._client = self._client, None
        self._nodes = {}
        if client is not None:
            await _disconnect(client)


async def _disconnect(client: Any) -> None:
    with contextlib.suppress(Exception):  # the session is already gone
        await bounded(client.disconnect(), 2.0, "disconnect")


class OpcUaServerPoint(Point):
    """A node the runtime serves: string id ``<object>.<variable>`` in the server's
    namespace (the object is created as a folder-like object under Objects)."""

    node: str = Field(min_length=1, pattern=r"^[^.]+\.[^.]+$")
    type: VariantName = "Float"
    writable: bool = False
    """Whether OPC UA clients may write it (inputs and parameters; outputs are read-only)."""

    def describe(self) -> str:
        return f"s={self.node} ({self.type}{', writable' if self.writable else ''})"


class OpcUaServerOptions(BaseModel):
    model_config = ConfigDict(extra="forbid")

    url: str = Field(
        default="opc.tcp://127.0.0.1:4840/fuzzyctl",
        pattern=r"^opc\.tcp://",
        description="endpoint to listen on; port 0 picks a free port",
    )
    namespace: str = "urn:fuzzyctl:runtime"
    name: str = "fuzzyctl runtime"


class OpcUaServer(Connector):
    """An OPC UA server exposing instance parameters as variables
    ``ns=<namespace>;s=<instance>.<parameter>`` under an object per instance."""

    point_model = OpcUaServerPoint
    options_model = OpcUaServerOptions
    options: OpcUaServerOptions
    server = True

    def __init__(self, name: str, options: OpcUaServerOptions) -> None:
        super().__init__(name, options)
        self._server: Any = None
        self._idx = 0
        self._objects: dict[str, Any] = {}
        self._nodes: dict[str, Any] = {}
        self.url = options.url

    def endpoint(self) -> str:
        return self.url

    @property
    def namespace_index(self) -> int:
        return self._idx

    async def connect(self) -> None:
        from asyncua.server.server import Server

        if self._server is not None:
            return
        server = Server()
        await server.init()
        server.set_endpoint(self.options.url)
        server.set_server_name(self.options.name)
        self._idx = await server.register_namespace(self.options.namespace)
        try:
            await server.start()
        except OSError as exc:
            raise LinkError(f"{self.options.url}: cannot listen: {exc}") from exc
        self._server = server
        self._objects, self._nodes = {}, {}
        sockets = getattr(getattr(getattr(server, "bserver", None), "_server", None), "sockets", None)
        if sockets:
            port = sockets[0].getsockname()[1]
            parts = urlsplit(self.options.url)
            self.url = urlunsplit(parts._replace(netloc=f"{parts.hostname}:{port}"))

    async def _node(self, p: OpcUaServerPoint) -> Any:
        from asyncua import ua

        node = self._nodes.get(p.node)
        if node is not None:
            return node
        obj_name, var_name = p.node.split(".", 1)
        obj = self._objects.get(obj_name)
        if obj is None:
            obj = self._objects[obj_name] = await self._server.nodes.objects.add_object(
                ua.NodeId(ua.String(obj_name), ua.Int16(self._idx)), ua.QualifiedName(obj_name, self._idx)
            )
        initial = math.nan if p.type in ("Float", "Double") else 0
        node = await obj.add_variable(
            ua.NodeId(ua.String(p.node), ua.Int16(self._idx)),
            ua.QualifiedName(var_name, self._idx),
            to_variant(initial, p.type).Value,
        )
        if p.writable:
            await node.set_writable()
        self._nodes[p.node] = node
        return node

    async def ensure(self, points: Sequence[Point]) -> None:
        """Create the nodes of ``points`` now (the runtime declares every node at start, so
        that clients can browse them before the first cycle)."""
        for p in points:
            assert isinstance(p, OpcUaServerPoint)
            await self._node(p)

    async def read(self, points: Sequence[Point]) -> list[float]:
        self.live(self._server, "not serving")
        out = []
        for p in points:
            assert isinstance(p, OpcUaServerPoint)
            node = await self._node(p)
            out.append(from_value(await node.read_value()))
        return out

    async def write(self, points: Sequence[Point], values: Sequence[float]) -> None:
        self.live(self._server, "not serving")
        for p, v in zip(points, values, strict=True):
            assert isinstance(p, OpcUaServerPoint)
            node = await self._node(p)
            await node.write_value(to_variant(v, p.type))

    async def close(self) -> None:
        server, self._server = self._server, None
        if server is not None:
            with contextlib.suppress(Exception):  # already stopped
                await server.stop()
