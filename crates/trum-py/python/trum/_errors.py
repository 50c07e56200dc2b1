"""Exceptions of trum. Messages are the core's, word for word (the CLI prints the same)."""
from __future__ import annotations

from typing import Optional, Type


class TrumError(Exception):
    """Base class of every error raised by trum."""

    def __str__(self) -> str:  # one message, also for the KeyError mixin below
        return str(self.args[0]) if self.args else ""


class ParameterError(TrumError, ValueError):
    """A motor parameter, preset name, effect or other model input is invalid.

    ``source``, ``line``, ``key`` and ``reason`` hold the parts of the message
    ("source: line N, key 'k': reason") when known.
    """

    def __init__(
        self,
        message: str,
        *,
        source: Optional[str] = None,
        line: Optional[int] = None,
        key: Optional[str] = None,
        reason: Optional[str] = None,
    ) -> None:
        super().__init__(message)
        self.source = source
        self.line = line
        self.key = key
        self.reason = reason


class ParameterKeyError(ParameterError, KeyError):
    """``motor[key]`` with a key that is not a motor parameter."""


class InputError(TrumError, ValueError):
    """An operating-point, sweep or criterion argument is invalid (bad axis, shapes that do not broadcast, ...)."""


def decode_utf8(raw: bytes, source: str, error: Type[TrumError]) -> str:
    """The text of a file's bytes; bytes that are not UTF-8 raise ``error`` naming the file,
    line, byte and offset, in the CLI's words."""
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        line = 1 + raw[: e.start].count(b"\n")
        raise error(
            f"{source}: line {line}: byte 0x{raw[e.start]:02X} at offset {e.start} is not valid UTF-8; "
            "save the file as UTF-8"
        ) from None
