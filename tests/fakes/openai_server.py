"""A real local HTTP server speaking the OpenAI chat-completions API, driven by a script.

Each POST to ``/v1/chat/completions`` takes the next script item: a :class:`Reply` (text answer with
usage), a :class:`Status` (HTTP error, optional ``retry-after``), a :class:`Delay` (wait, then serve
another item; makes clients time out), :class:`Raw` (any body) or :class:`Close` (drop the connection
without answering) or :class:`Reset` (abort the connection with a TCP reset), :class:`Trickle` (a
body, or headers and body, one byte at a time) or :class:`Huge` (a body of any size, streamed).
A plain string in a script is a Reply. Requests are recorded in ``server.requests``. Binds to
127.0.0.1 on a free port; use it as a context manager::

    with FakeOpenAIServer(["{\"room\": \"kitchen\"}", Status(429, retry_after=0)]) as server:
        ...  # point the client at server.base_url
"""

from __future__ import annotations

import json
import socket
import struct
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any


@dataclass(frozen=True)
class Reply:
    """A successful chat completion with this text and usage."""

    text: str
    prompt_tokens: int | float | None = 100
    completion_tokens: int | float | None = 20
    """Usage as sent: a hostile server's may be negative, 1e300 or null."""
    model: str | None = None
    """Model name in the response; None echoes the requested model."""


@dataclass(frozen=True)
class Status:
    """An HTTP error status with an OpenAI-style error body."""

    code: int
    message: str = "fake error"
    retry_after: float | None = None


@dataclass(frozen=True)
class Delay:
    """Wait ``seconds`` (cut short when the server stops), then serve ``then``."""

    seconds: float
    then: Reply | Status = field(default_factory=lambda: Reply("{}"))


@dataclass(frozen=True)
class Raw:
    """Any body with any status, e.g. a proxy's HTML error page with status 200."""

    body: bytes
    status: int = 200
    content_type: str = "text/html"


@dataclass(frozen=True)
class Close:
    """Drop the connection without sending a response."""


@dataclass(frozen=True)
class Reset:
    """Abort the connection with a TCP reset (``SO_LINGER`` 0): the client sees ECONNRESET."""


@dataclass(frozen=True)
class Trickle:
    """Serve ``then`` one byte every ``interval_s`` seconds: only its body, or (``headers``) the whole response."""

    then: Reply
    interval_s: float = 1.0
    headers: bool = False


@dataclass(frozen=True)
class Huge:
    """A 200 response whose body is ``size`` bytes of JSON-looking padding, streamed in 64 kB pieces
    (never held in memory); ``declare_length=False`` sends it without a Content-Length (close-delimited)."""

    size: int
    declare_length: bool = True


ScriptItem = Reply | Status | Delay | Raw | Close | Reset | Trickle | Huge


@dataclass(frozen=True)
class RecordedRequest:
    """One request the server received."""

    path: str
    headers: dict[str, str]
    """Header names in lower case."""
    body: dict[str, Any]


EXHAUSTED = Status(500, "fake server: script exhausted")


class FakeOpenAIServer:
    """Scripted OpenAI-compatible server on 127.0.0.1.

    Pushed script items answer first; once they are used up, ``responder(request body)`` answers if
    given (a scripted "brain" that reads the prompt), else ``default``.
    """

    def __init__(
        self,
        script: Iterable[ScriptItem | str] = (),
        *,
        default: ScriptItem | str = EXHAUSTED,
        responder: Callable[[dict[str, Any]], ScriptItem | str] | None = None,
    ) -> None:
        self._script: deque[ScriptItem] = deque()
        self.push(*script)
        self._default = Reply(default) if isinstance(default, str) else default
        self._responder = responder
        self.requests: list[RecordedRequest] = []
        self._lock = threading.Lock()
        self._stopped = threading.Event()
        self._httpd: ThreadingHTTPServer | None = None
        self._thread: threading.Thread | None = None

    def push(self, *items: ScriptItem | str) -> None:
        """Append items to the script."""
        self._script.extend(Reply(i) if isinstance(i, str) else i for i in items)

    @property
    def port(self) -> int:
        """The bound port (after start)."""
        assert self._httpd is not None, "server not started"
        return self._httpd.server_address[1]

    @property
    def base_url(self) -> str:
        """What to give a client as base URL."""
        return f"http://127.0.0.1:{self.port}/v1"

    def _next(self, request: RecordedRequest) -> ScriptItem:
        with self._lock:
            self.requests.append(request)
            if self._script or self._responder is None:
                return self._script.popleft() if self._script else self._default
        answer = self._responder(request.body)
        return Reply(answer) if isinstance(answer, str) else answer

    def start(self) -> FakeOpenAIServer:
        """Bind and serve in a daemon thread."""
        server = self
        handler = type("Handler", (_Handler,), {"fake": server})
        self._httpd = ThreadingHTTPServer(("127.0.0.1", 0), handler)
        self._httpd.daemon_threads = True
        self._httpd.block_on_close = False
        self._thread = threading.Thread(target=self._httpd.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stop serving and free the port (pending delays end at once)."""
        self._stopped.set()
        if self._httpd is not None:
            self._httpd.shutdown()
            self._httpd.server_close()
        if self._thread is not None:
            self._thread.join(timeout=5)

    def __enter__(self) -> FakeOpenAIServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


class _Handler(BaseHTTPRequestHandler):
    protocol_version = "HTTP/1.1"
    disable_nagle_algorithm = True
    """Headers and body go out as two writes: with Nagle's algorithm the body waits for the client's
    delayed ACK of the headers, 40 ms a response on Linux (a test episode of 50 requests waited 2 s)."""
    fake: FakeOpenAIServer

    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 - stdlib signature
        """Silence the default stderr log."""

    def _send_json(self, code: int, body: dict[str, Any], headers: dict[str, str] | None = None) -> None:
        self._send(code, json.dumps(body).encode(), "application/json", headers)

    def _send(self, code: int, data: bytes, content_type: str, headers: dict[str, str] | None = None) -> None:
        try:
            self.send_response(code)
            self.send_header("Content-Type", content_type)
            self.send_header("Content-Length", str(len(data)))
            for k, v in (headers or {}).items():
                self.send_header(k, v)
            self.end_headers()
            self.wfile.write(data)
        except (BrokenPipeError, ConnectionResetError):
            self.close_connection = True

    def _serve(self, item: ScriptItem, body: dict[str, Any]) -> None:
        if isinstance(item, Trickle):
            self._trickle(item, body)
        elif isinstance(item, Huge):
            self._huge(item)
        elif isinstance(item, Delay):
            self.fake._stopped.wait(item.seconds)
            self._serve(item.then, body)
        elif isinstance(item, Raw):
            self._send(item.status, item.body, item.content_type)
        elif isinstance(item, Close):
            self.close_connection = True
        elif isinstance(item, Reset):
            self.connection.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            self.close_connection = True
        elif isinstance(item, Status):
            headers = {"retry-after": f"{item.retry_after:g}"} if item.retry_after is not None else {}
            self._send_json(item.code, {"error": {"message": item.message, "type": "fake", "code": None}}, headers)
        else:
            self._send_json(200, self._completion(item, body))

    def _completion(self, item: Reply, body: dict[str, Any]) -> dict[str, Any]:
        """The chat-completion JSON of ``item`` (usage sent as given, however wrong)."""
        p, c = item.prompt_tokens, item.completion_tokens
        return {
            "id": f"chatcmpl-fake-{len(self.fake.requests)}",
            "object": "chat.completion",
            "created": int(time.time()),
            "model": item.model or body.get("model", "fake-model"),
            "choices": [{"index": 0, "message": {"role": "assistant", "content": item.text}, "finish_reason": "stop"}],
            "usage": {"prompt_tokens": p, "completion_tokens": c,
                      "total_tokens": None if p is None or c is None else p + c},
        }

    def _trickle(self, item: Trickle, body: dict[str, Any]) -> None:
        data = json.dumps(self._completion(item.then, body)).encode()
        head = (f"HTTP/1.1 200 OK\r\nContent-Type: application/json\r\nContent-Length: {len(data)}\r\n\r\n").encode()
        self.close_connection = True
        try:
            if not item.headers:
                self.wfile.write(head)
                self.wfile.flush()
            for i in range(len(data) + (len(head) if item.headers else 0)):
                if self.fake._stopped.wait(item.interval_s):
                    return
                byte = (head + data)[i:i + 1] if item.headers else data[i:i + 1]
                self.wfile.write(byte)
                self.wfile.flush()
        except (BrokenPipeError, ConnectionResetError):
            pass

    def _huge(self, item: Huge) -> None:
        self.close_connection = True
        piece = b" " * 65536
        try:
            self.send_response(200)
            self.send_header("Content-Type", "application/json")
            if item.declare_length:
                self.send_header("Content-Length", str(item.size))
            self.end_headers()
            sent = 0
            while sent < item.size and not self.fake._stopped.is_set():
                chunk = piece[: item.size - sent]
                self.wfile.write(chunk)
                sent += len(chunk)
        except (BrokenPipeError, ConnectionResetError):
            pass

    def do_POST(self) -> None:
        raw = self.rfile.read(int(self.headers.get("Content-Length", 0)))
        if self.path.rstrip("/") != "/v1/chat/completions":
            self._send_json(404, {"error": {"message": f"no route {self.path}", "type": "fake", "code": None}})
            return
        try:
            body = json.loads(raw or b"{}")
        except json.JSONDecodeError:
            self._send_json(400, {"error": {"message": "body is not JSON", "type": "fake", "code": None}})
            return
        item = self.fake._next(RecordedRequest(self.path, {k.lower(): v for k, v in self.headers.items()}, body))
        self._serve(item, body)


def request_text(body: dict[str, Any]) -> str:
    """The text of a request's last message (its text parts joined when it carries images)."""
    content = body["messages"][-1]["content"]
    if isinstance(content, str):
        return content
    return "\n".join(p["text"] for p in content if p.get("type") == "text")


def request_images(body: dict[str, Any]) -> list[bytes]:
    """The images of a request's messages (base64 data URLs of ``image_url`` parts), decoded, in order."""
    import base64

    return [
        base64.b64decode(p["image_url"]["url"].split(";base64,", 1)[1])
        for m in body["messages"] if isinstance(m["content"], list)
        for p in m["content"] if p.get("type") == "image_url"
    ]
