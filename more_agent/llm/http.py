"""Bounded HTTP for the OpenAI-compatible backend: one wall-clock deadline per request, and a body cap.

httpx's timeouts bound each socket operation, not the request: a server that sends one byte a
second never trips a 3 s read timeout and holds a run forever. Here every request gets a deadline
``timeout_s`` after it starts; connecting, sending, reading the headers and reading the body all
share it (each socket operation waits at most what is left), so the request ends within
``timeout_s`` whatever the server does, as an ``httpx2.ReadTimeout`` (the backend's
:class:`~more_agent.llm.errors.LLMTimeout`, retried like any timeout). A response body over
:data:`MAX_BODY_BYTES` (by its Content-Length or as it arrives) stops the read with
:class:`BodyTooLarge` (the backend's ``LLMResponseTooLarge``, never retried): memory stays bounded
whatever a server sends. Imported only when the first request is sent (it imports httpx).
"""

from __future__ import annotations

import functools
import ssl
import threading
import time
from collections.abc import Iterable, Iterator
from typing import Any

import httpcore2
import httpx2

MAX_BODY_BYTES = 8 * 1024 * 1024
"""Largest response body read (a valid answer is under 100 kB; ``MAX_ANSWER_CHARS`` is 16,000)."""


class BodyTooLarge(Exception):
    """A response body is over the cap; ``size`` is what was known of it when reading stopped."""

    def __init__(self, size: int, limit: int) -> None:
        super().__init__(f"the response body is over {limit} bytes ({size} or more)")
        self.size, self.limit = size, limit


_deadline = threading.local()
"""The deadline (``time.monotonic()`` value) of the request this thread is sending, if any."""


def _left(timeout: float | None) -> float | None:
    """``timeout`` shortened to what is left of this thread's request deadline; raises when none is left."""
    end = getattr(_deadline, "at", None)
    if end is None:
        return timeout
    left = end - time.monotonic()
    if left <= 0:
        raise httpcore2.ReadTimeout("the request's deadline passed")
    return left if timeout is None else min(timeout, left)


def _deadline_stream(stream: Any) -> Any:
    """A network stream whose every read and write waits at most what is left of the deadline."""

    class DeadlineStream(httpcore2.NetworkStream):
        def read(self, max_bytes: int, timeout: float | None = None) -> bytes:
            return stream.read(max_bytes, _left(timeout))

        def write(self, buffer: bytes, timeout: float | None = None) -> None:
            stream.write(buffer, _left(timeout))

        def close(self) -> None:
            stream.close()

        def start_tls(self, ssl_context: Any, server_hostname: str | None = None, timeout: float | None = None) -> Any:
            return _deadline_stream(stream.start_tls(ssl_context, server_hostname, _left(timeout)))

        def get_extra_info(self, info: str) -> Any:
            return stream.get_extra_info(info)

    return DeadlineStream()


def _deadline_backend() -> Any:
    """httpcore's sync network backend with every connection's socket operations under the deadline."""
    inner = httpcore2.SyncBackend()

    class DeadlineBackend(httpcore2.NetworkBackend):
        def connect_tcp(
            self,
            host: str,
            port: int,
            timeout: float | None = None,
            local_address: str | None = None,
            socket_options: Iterable[Any] | None = None,
        ) -> Any:
            return _deadline_stream(inner.connect_tcp(host, port, _left(timeout), local_address, socket_options))

        def connect_unix_socket(
            self, path: str, timeout: float | None = None, socket_options: Iterable[Any] | None = None
        ) -> Any:
            return _deadline_stream(inner.connect_unix_socket(path, _left(timeout), socket_options))

        def sleep(self, seconds: float) -> None:
            inner.sleep(seconds)

    return DeadlineBackend()


@functools.cache
def _ssl_context() -> ssl.SSLContext:
    """httpx's default TLS context, built once per process: loading the CA bundle takes ~25 ms, and every
    episode's client would do it again (contexts are safe to share between threads)."""
    return httpx2.create_ssl_context()


def bounded_client(timeout_s: float, *, max_body_bytes: int = MAX_BODY_BYTES) -> httpx2.Client:
    """An ``httpx2.Client`` whose requests each end within ``timeout_s`` and read at most ``max_body_bytes``."""

    class BoundedTransport(httpx2.HTTPTransport):
        def handle_request(self, request: httpx2.Request) -> httpx2.Response:
            _deadline.at = time.monotonic() + timeout_s
            try:
                response = super().handle_request(request)
            except BaseException:
                _deadline.at = None
                raise
            length = response.headers.get("content-length", "")
            if length.isdigit() and int(length) > max_body_bytes:
                response.close()
                _deadline.at = None
                raise BodyTooLarge(int(length), max_body_bytes)
            return httpx2.Response(
                response.status_code,
                headers=response.headers,
                stream=_CappedStream(response.stream, max_body_bytes),
                extensions=response.extensions,
            )

    transport = BoundedTransport(verify=_ssl_context())
    # httpx builds its connection pool without a choice of network backend; the deadline lives there.
    transport._pool._network_backend = _deadline_backend()  # noqa: SLF001 - checked by tests/llm/test_http_bounds.py
    return httpx2.Client(transport=transport, timeout=timeout_s)


class _CappedStream(httpx2.SyncByteStream):
    """A response body stream that stops past ``limit`` bytes and ends the request's deadline when done."""

    def __init__(self, inner: Any, limit: int) -> None:
        self._inner, self._limit, self._read = inner, limit, 0

    def __iter__(self) -> Iterator[bytes]:
        try:
            for chunk in self._inner:
                self._read += len(chunk)
                if self._read > self._limit:
                    raise BodyTooLarge(self._read, self._limit)
                yield chunk
        finally:
            _deadline.at = None

    def close(self) -> None:
        self._inner.close()
        _deadline.at = None
