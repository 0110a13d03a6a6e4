"""What the operation mixins (``ProgramOps``, ``ChannelOps``, ``TraceOps``,
``AlarmOps``, ``MachineOps``) need of the client they are mixed into: the object and raw-address
requests of ``AsyncClient`` and its transport's pause. Declared as a Protocol so that
mypy checks the mixins' bodies; at run time the mixins derive from ``object``."""

from __future__ import annotations

from collections.abc import AsyncIterator, Awaitable, Iterable
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from .object_info import ObjectInfo

#: Samples a subscription keeps for its reader by default; a full buffer drops the oldest.
SAMPLE_BUFFER = 1000


class Pausing(Protocol):
    """The transport's wall-clock wait (asyncio's sleep, or the blocking driver's)."""

    def pause(self, seconds: float) -> Awaitable[None]:
        """Wait ``seconds`` of wall time."""
        ...


class ClientCore(Protocol):
    """The requests of ``AsyncClient`` that the operation mixins build on."""

    _t: Pausing

    async def browse(self, pattern: str = "*") -> list[ObjectInfo]:
        """Descriptions of the objects whose names match ``pattern``."""
        ...

    async def describe(self, name: str) -> ObjectInfo:
        """What the service says about the object ``name``."""
        ...

    async def read(self, name: str, units: bool = False) -> Any:
        """Read the object ``name``."""
        ...

    async def write(self, name: str, value: Any, units: bool = False) -> None:
        """Write the object ``name``."""
        ...

    async def read_many(self, names: Iterable[str], units: bool = False) -> dict[str, Any]:
        """Read several objects in one round trip."""
        ...

    def subscribe(
        self, name: str, on_change: bool = True, cycle_ms: int | None = None,
        units: bool = False, buffer_samples: int | None = SAMPLE_BUFFER,
    ) -> AsyncIterator[Any]:
        """Samples of ``name`` as the service sends them."""
        ...

    async def read_raw(self, port: int, group: int, offset: int, length: int) -> bytes:
        """Read raw bytes at an ADS address."""
        ...

    async def write_raw(self, port: int, group: int, offset: int, data: bytes) -> None:
        """Write raw bytes at an ADS address."""
        ...

    async def read_write_raw(
        self, port: int, group: int, offset: int, data: bytes, read_length: int
    ) -> bytes:
        """ADS ReadWrite at an address."""
        ...


if TYPE_CHECKING:
    #: The base of the mixins: the Protocol for mypy, plain ``object`` at run time.
    MixinBase = ClientCore
else:
    MixinBase = object
