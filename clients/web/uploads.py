"""Programs as big as CAM writes them, from the browser: a chunked upload through cnc-web.

The page sends the file in slices of at most ``SLICE_MAX_BYTES``, each one HTTP request,
and cnc-web forwards each slice to the service's chunked upload as its bytes arrive
(``ChunkedUpload``, frames of ``UPLOAD_CHUNK_BYTES``): cnc-web holds one frame of a
program, never the program.

    POST   /api/uploads             {"name", "size_bytes"} -> {"upload", "slice_bytes"}
    PUT    /api/uploads/{id}?at=N   the slice's bytes       -> {"received_bytes"}
    POST   /api/uploads/{id}/commit                         -> {"name", "size_bytes"}
    DELETE /api/uploads/{id}                                   (cancel)

The service takes one upload per connection, so each upload has a service connection of
its own, opened with cnc-web's key and closed when the upload ends. An upload is the
session's that opened it (another session gets 404). It is abandoned, and nothing stays
in the store, when: a slice does not arrive whole (the tab closed, the connection
dropped, Cancel), a slice is out of order or beyond the announced size, the service
refuses a chunk (its limits), no slice came for ``idle_s`` (a tab closed between slices),
or cnc-web stops. At most ``max_uploads`` run at once.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import secrets
from collections.abc import Callable
from dataclasses import dataclass, field

from aiohttp import StreamReader

from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.program_upload import ChunkedUpload
from cnc_objects.protocol.constants import UPLOAD_CHUNK_BYTES

log = logging.getLogger(__name__)

SLICE_BYTES = 4 << 20  # what the page sends per request
SLICE_MAX_BYTES = 8 << 20  # a request with more is refused before it is read
IDLE_S = 30.0  # wall time an upload waits for its next slice; then it is abandoned
MAX_UPLOADS = 4  # uploads at once (each holds a service connection)


class UploadRefused(Exception):
    """A request about an upload that cannot be done, with the HTTP status and sentence."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status


@dataclass(eq=False)
class WebUpload:
    """One browser upload in progress and its own service connection."""

    id: str
    owner: str  # the session's CSRF token: the upload is that session's
    name: str
    size_bytes: int
    client: AsyncClient
    upload: ChunkedUpload
    busy: bool = False  # a slice is being forwarded
    timer: asyncio.TimerHandle | None = field(default=None, repr=False)

    @property
    def received_bytes(self) -> int:
        """Bytes forwarded to the service so far."""
        return self.upload.sent_bytes


class WebUploads:
    """The uploads in progress of one cnc-web; ``connect()`` makes a service client."""

    def __init__(self, connect: Callable[[], AsyncClient], idle_s: float = IDLE_S,
                 max_uploads: int = MAX_UPLOADS) -> None:
        self._connect = connect
        self.idle_s = idle_s
        self.max_uploads = max_uploads
        self._uploads: dict[str, WebUpload] = {}
        self._ending: set[asyncio.Task[None]] = set()

    def __len__(self) -> int:
        return len(self._uploads)

    async def open(self, owner: str, name: str, size_bytes: int) -> WebUpload:
        """Start an upload of ``name`` (``size_bytes``) on a connection of its own; the
        service refuses a name or a size its limits do not take (``AdsError``)."""
        if len(self._uploads) >= self.max_uploads:
            raise UploadRefused(503, f"cnc-web runs {self.max_uploads} uploads at once; "
                                "try again when one has finished")
        client = self._connect()
        await client.__aenter__()
        upload = WebUpload(secrets.token_urlsafe(16), owner, name, size_bytes, client,
                           client.chunked_upload(name, size_bytes))
        try:
            await upload.upload.open()
        except BaseException:
            await client.__aexit__(None, None, None)
            raise
        self._uploads[upload.id] = upload
        self._arm(upload)
        log.info("upload of %r (%d bytes) opened", name, size_bytes)
        return upload

    def get(self, upload_id: str, owner: str) -> WebUpload:
        """The upload ``upload_id`` of the session ``owner``."""
        upload = self._uploads.get(upload_id)
        if upload is None or upload.owner != owner:
            raise UploadRefused(404, "no such upload (it finished, was cancelled, or was "
                                "abandoned: an error, a dropped slice, or idle too long)")
        return upload

    async def slice(self, upload: WebUpload, at: int, length: int,
                    body: StreamReader) -> int:
        """Forward the slice of ``length`` bytes starting at byte ``at``, read from
        ``body`` piece by piece; the bytes received so far. Anything wrong, a body that
        ends early included, abandons the upload."""
        if upload.busy:
            raise UploadRefused(409, f"upload of {upload.name!r}: a slice is already on its "
                                "way; send the next when it is answered")
        why = self._slice_fault(upload, at, length)
        if why is not None:
            await self.abandon(upload, why)
            raise UploadRefused(400, why + "; the upload is abandoned")
        upload.busy = True
        self._disarm(upload)
        try:
            pending = bytearray()
            async for piece in body.iter_chunked(UPLOAD_CHUNK_BYTES):
                pending += piece
                if len(pending) >= UPLOAD_CHUNK_BYTES:
                    await upload.upload.write(bytes(pending))
                    pending.clear()
            await upload.upload.write(bytes(pending))
            if upload.received_bytes != at + length:
                raise UploadRefused(400, f"upload of {upload.name!r}: the slice at byte {at} "
                                    f"brought {upload.received_bytes - at} of its {length} bytes")
        except BaseException as exc:  # a refusal, the service's, a dropped connection
            await self.abandon(upload, f"a slice failed ({type(exc).__name__}: {exc})")
            raise
        upload.busy = False
        self._arm(upload)
        return upload.received_bytes

    @staticmethod
    def _slice_fault(upload: WebUpload, at: int, length: int) -> str | None:
        if at != upload.received_bytes:
            return (f"upload of {upload.name!r}: a slice at byte {at}, expected byte "
                    f"{upload.received_bytes}")
        if at + length > upload.size_bytes:
            return (f"upload of {upload.name!r}: a slice up to byte {at + length}, beyond the "
                    f"{upload.size_bytes} bytes announced")
        return None

    async def commit(self, upload: WebUpload) -> int:
        """Finish: the program replaces its older version atomically; its size."""
        if upload.busy:
            raise UploadRefused(409, f"upload of {upload.name!r}: a slice is still on its way")
        if upload.received_bytes != upload.size_bytes:
            why = (f"upload of {upload.name!r}: {upload.received_bytes} of its "
                   f"{upload.size_bytes} bytes arrived")
            await self.abandon(upload, why)
            raise UploadRefused(400, why + "; the upload is abandoned")
        try:
            size = await upload.upload.commit()
        finally:
            await self._end(upload)
        log.info("upload of %r committed (%d bytes)", upload.name, size)
        return size

    async def abandon(self, upload: WebUpload, why: str) -> None:
        """Drop ``upload``: the service removes what arrived, its connection closes."""
        if self._uploads.get(upload.id) is not upload:
            return
        log.info("upload of %r abandoned after %d bytes: %s", upload.name,
                 upload.received_bytes, why)
        with contextlib.suppress(Exception):  # the connection's end abandons it anyway
            await upload.upload.abandon()
        await self._end(upload)

    async def _end(self, upload: WebUpload) -> None:
        self._disarm(upload)
        self._uploads.pop(upload.id, None)
        with contextlib.suppress(Exception):
            await upload.client.__aexit__(None, None, None)

    async def close(self) -> None:
        """cnc-web stops: every upload is abandoned."""
        for upload in list(self._uploads.values()):
            await self.abandon(upload, "cnc-web stops")

    def _arm(self, upload: WebUpload) -> None:
        self._disarm(upload)
        loop = asyncio.get_running_loop()
        upload.timer = loop.call_later(self.idle_s, self._expire, upload)

    @staticmethod
    def _disarm(upload: WebUpload) -> None:
        if upload.timer is not None:
            upload.timer.cancel()
            upload.timer = None

    def _expire(self, upload: WebUpload) -> None:
        upload.timer = None
        task = asyncio.create_task(self.abandon(
            upload, f"no slice came for {self.idle_s:g} s"), name=f"abandon {upload.name}")
        self._ending.add(task)
        task.add_done_callback(self._ending.discard)
