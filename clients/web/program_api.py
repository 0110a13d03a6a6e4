"""cnc-web's API for programs as big as CAM writes them: the chunked upload from the
browser (``uploads.py``) and the program view's window of lines.

Uploads are the program store's, admin's (``STORE_ROLE``, as the service decides), with
the session's CSRF token, like every write; the window of lines is a read (any role).
"""

from __future__ import annotations

from collections.abc import Awaitable, Callable

from aiohttp import web

from cnc_objects.protocol.program_lines import LINES_MAX

from .access import STORE_ROLE, refusal, require_write
from .api import CLIENT_KEY, _body, _field, _query_count, _service_call
from .uploads import SLICE_BYTES, SLICE_MAX_BYTES, UploadRefused, WebUpload, WebUploads

UPLOADS_KEY: web.AppKey[WebUploads] = web.AppKey("uploads")
WINDOW_LINES_MAX = 1000  # lines one view request may ask for
Handler = Callable[[web.Request], Awaitable[web.StreamResponse]]


def _uploads(request: web.Request) -> WebUploads:
    return request.app[UPLOADS_KEY]


def _upload(request: web.Request, what: str) -> WebUpload:
    """The upload the path names, when it is this session's (and its role may upload)."""
    session = require_write(request, what, STORE_ROLE)
    try:
        return _uploads(request).get(request.match_info["upload"], session.csrf)
    except UploadRefused as exc:
        raise refusal(exc.status, str(exc)) from None


def _upload_refusals(handler: Handler) -> Handler:
    """Answer an ``UploadRefused`` with its status and sentence."""

    async def wrapped(request: web.Request) -> web.StreamResponse:
        try:
            return await handler(request)
        except UploadRefused as exc:
            raise refusal(exc.status, str(exc)) from None

    return wrapped


@_service_call
@_upload_refusals
async def open_upload(request: web.Request) -> web.StreamResponse:
    """Start a chunked upload of ``name`` (``size_bytes``): the service refuses a name,
    or a size over its limits, here, in its words."""
    data = await _body(request)
    name = _field(data, "name", str)
    size_bytes = _field(data, "size_bytes", int)
    session = require_write(request, "upload programs", STORE_ROLE)
    if size_bytes < 0:
        raise refusal(400, f"'size_bytes' is {size_bytes}: a size is >= 0")
    upload = await _uploads(request).open(session.csrf, name, size_bytes)
    return web.json_response({"upload": upload.id, "slice_bytes": SLICE_BYTES})


@_service_call
@_upload_refusals
async def upload_slice(request: web.Request) -> web.StreamResponse:
    """The next slice of an upload (the body; ``at``: where it starts), forwarded to the
    service as it is read."""
    upload = _upload(request, "upload programs")
    at = _query_count(request, "at", 0) if "at" in request.query else -1
    length = request.content_length
    if at < 0 or length is None:
        await _uploads(request).abandon(upload, "a slice without 'at' or Content-Length")
        raise refusal(400, "a slice needs ?at=<its first byte> and a Content-Length; "
                           "the upload is abandoned")
    if length > SLICE_MAX_BYTES:
        await _uploads(request).abandon(upload, f"a slice of {length} bytes")
        raise refusal(400, f"a slice has at most {SLICE_MAX_BYTES} bytes, not {length}; "
                           "the upload is abandoned")
    received = await _uploads(request).slice(upload, at, length, request.content)
    return web.json_response({"received_bytes": received, "size_bytes": upload.size_bytes})


@_service_call
@_upload_refusals
async def commit_upload(request: web.Request) -> web.StreamResponse:
    """Finish an upload: the program replaces its older version atomically."""
    upload = _upload(request, "upload programs")
    size = await _uploads(request).commit(upload)
    return web.json_response({"name": upload.name, "size_bytes": size})


@_service_call
@_upload_refusals
async def cancel_upload(request: web.Request) -> web.StreamResponse:
    """Cancel an upload: nothing of it stays in the store."""
    upload = _upload(request, "upload programs")
    await _uploads(request).abandon(upload, "cancelled on the page")
    return web.json_response({"ok": True})


@_service_call
async def program_lines(request: web.Request) -> web.StreamResponse:
    """Lines ``first``.. (from 1, at most ``count``) of a stored program and how many it
    has: the service reads that window only, whatever the program's size."""
    first = _query_count(request, "first", 1)
    count = _query_count(request, "count", 200)
    if first < 1 or not 0 < count <= min(WINDOW_LINES_MAX, LINES_MAX):
        raise refusal(400, f"'first' is a line number from 1 and 'count' 1..{WINDOW_LINES_MAX}")
    name = request.match_info["name"]
    window = await request.app[CLIENT_KEY].program_lines(name, first, count)
    return web.json_response({"name": name, "first_line": window.first_line,
                              "total_lines": window.total_lines, "lines": window.lines})


def add_routes(app: web.Application) -> None:
    """The routes of the chunked upload and of the window of lines (``UPLOADS_KEY`` is
    set when the service client starts)."""
    app.add_routes([
        web.post("/api/uploads", open_upload),
        web.put("/api/uploads/{upload}", upload_slice),
        web.post("/api/uploads/{upload}/commit", commit_upload),
        web.delete("/api/uploads/{upload}", cancel_upload),
        web.get("/api/programs/{name}/lines", program_lines),
    ])

