"""The NC program decoder (SDA task): DIN 66025 with the ISG extensions.

Public API: ``Decoder`` (text -> lazy stream of ``Block``), ``ModalState`` (what
survives between decoders), ``NcError`` / ``NcErrorId`` (every error with id, file,
line and column), ``check_syntax`` (all parse errors of a file at once). The output
contract is in ``blocks``.
"""

from .blocks import (
    AxisExchange,
    AxisExchangeKind,
    Block,
    Compensation,
    ContourCommand,
    ContourKind,
    LogArea,
    Motion,
    MotionKind,
    SourceRef,
    StopKind,
    next_log_area,
)
from .decoder import Decoder
from .errors import NcError, NcErrorId
from .modal import DistanceMode, ModalState, Plane
from .syntax import check_syntax

__all__ = [
    "AxisExchange", "AxisExchangeKind", "Block", "Compensation", "ContourCommand",
    "ContourKind", "Decoder", "DistanceMode", "LogArea", "ModalState", "Motion", "MotionKind",
    "NcError", "NcErrorId", "Plane", "SourceRef", "StopKind", "check_syntax", "next_log_area",
]
