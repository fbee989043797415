"""The exceptions of situ: each has a ``code`` (a finding's code such as
``E0104``, or a kind such as ``unknown-event``) and a message; a
:class:`FindingsError` also carries the findings."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Optional

if TYPE_CHECKING:
    from .findings import Finding


class Error(Exception):
    """Anything situ refuses. ``code`` says what kind."""

    code: str
    message: str

    def __init__(self, message: str, code: str, detail: Optional[str] = None) -> None:
        super().__init__(message)
        self.message = message
        self.code = code
        self._detail = detail

    def __str__(self) -> str:
        return f"[{self.code}] {self.message}"


class ReadError(Error):
    """A file could not be read (missing, not a regular file, too large)."""


class WriteError(Error):
    """An output could not be written."""


class FindingsError(Error):
    """The rules have errors (or warnings, when they are denied). ``code`` is
    the first error's code; ``findings`` holds them all, with their places."""

    @property
    def findings(self) -> list[Finding]:
        from .findings import Finding

        return [Finding.from_json(f) for f in json.loads(self._detail or "[]")]


class SituSyntaxError(FindingsError):
    """A source with syntax errors was not formatted."""


class BundleError(Error):
    """A bundle is damaged, of another format version, or was changed."""


class TrustError(Error):
    """A bundle is not signed by a trusted key, a source was given where only
    signed bundles are trusted, or a key file could not be read."""


class RecordingError(Error):
    """A recording is not one situ can read."""


class BoardError(Error):
    """A wrong call on a board: an event, field or value the rules do not
    have (``unknown-event``, ``not-its-agent``, ``unknown-field``,
    ``missing-fields``, ``field-twice``, ``field-type``), a time that is not
    one (``bad-time``), or rules that cannot take over (``reload``).
    Nothing changed."""
