"""The workbench as a Starlette application: the static page, its offline assets and the JSON endpoints.

Every ``POST`` takes a JSON body of at most :data:`MAX_BODY_BYTES` (read in chunks, refused as soon as it is
larger), ``Content-Type: application/json`` (a plain HTML form of another site cannot send one without the
browser asking first), and answers JSON; an error is ``{"error": one line, "cell": {row, field} | null}`` with
a 4xx status.  The ``Host`` header must name the address the server listens on (DNS rebinding).  Quick
answers (kinematics, IK, M/c/g, statics) run on the event loop; long work goes to :class:`~._jobs.Jobs`.
"""

from __future__ import annotations

import contextlib
import json
import threading
from collections.abc import Callable
from importlib import resources
from typing import Any

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.middleware import Middleware
from starlette.middleware.trustedhost import TrustedHostMiddleware
from starlette.requests import Request
from starlette.responses import HTMLResponse, JSONResponse, Response
from starlette.routing import Route

from . import _handlers as H
from . import _ik
from ._jobs import Jobs

__all__ = ["MAX_BODY_BYTES", "MAX_CHECK_BYTES", "create_app"]

#: Largest JSON body of a request (a 64-row table with inertial data is about 20 kB).
MAX_BODY_BYTES = 256_000
#: Largest body of a check job or an opened file (the report, claims, robot file or URDF text travels inside it).
MAX_CHECK_BYTES = 1_200_000
_STATIC = {"workbench.js": "text/javascript", "jobs.js": "text/javascript", "workbench.css": "text/css"}


def _asset(name: str) -> str:
    return resources.files("denavit.web").joinpath("static", name).read_text(encoding="utf-8")


async def _read_json(request: Request, limit: int = MAX_BODY_BYTES) -> Any:
    """The request's JSON body, read at most ``limit`` bytes far."""
    ctype = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if ctype != "application/json":
        raise H.RequestError("send the request as Content-Type: application/json", 415)
    declared = request.headers.get("content-length", "")
    if declared.isdigit() and int(declared) > limit:
        raise H.RequestError(f"request body too large ({declared} bytes; at most {limit})", 413)
    chunks, size = [], 0
    async for chunk in request.stream():
        size += len(chunk)
        if size > limit:
            raise H.RequestError(f"request body too large (more than {limit} bytes)", 413)
        chunks.append(chunk)
    try:
        return json.loads(b"".join(chunks).decode("utf-8"), parse_constant=_no_constant)
    except RecursionError:
        raise H.RequestError("request body nested too deeply", 400) from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise H.RequestError(f"request body is not JSON: {exc}", 400) from None


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number")


def _error(exc: H.RequestError) -> JSONResponse:
    return JSONResponse(exc.to_json(), status_code=exc.status)


def _post(handler: Callable[[Any], dict[str, Any]], limit: int = MAX_BODY_BYTES, threaded: bool = False) -> Callable:
    """An endpoint calling ``handler(body)``: its dict as JSON, or the one-line error.  ``threaded``: in a worker
    thread (an answer that can take a few tenths of a second, the general-6R IK, must not hold the event loop,
    where the slider answers run)."""

    async def endpoint(request: Request) -> Response:
        try:
            body = await _read_json(request, limit)
            return JSONResponse(await run_in_threadpool(handler, body) if threaded else handler(body))
        except H.RequestError as exc:
            return _error(exc)
        except RecursionError:
            return _error(H.RequestError("input nested too deeply", 400))
        except MemoryError:
            return _error(H.RequestError("the input asks for more memory than this machine can give", 413))

    return endpoint


def create_app(robot: Any = None, *, allowed_hosts: list[str] | None = None, jobs: Jobs | None = None) -> Starlette:
    """The workbench application.

    Parameters
    ----------
    robot : DHRobot, optional
        The arm the page opens with (the file or name given on the command line); puma560 when None.
    allowed_hosts : list of str, optional
        Host header values accepted (default: the loopback names).
    jobs : Jobs, optional
        The job runner (tests pass one with a small CPU limit).
    """
    from ..io import robot_to_dict

    jobs = jobs or Jobs()
    hosts = allowed_hosts or ["127.0.0.1", "localhost", "[::1]"]
    app = Starlette(routes=_routes(), middleware=[Middleware(TrustedHostMiddleware, allowed_hosts=hosts)],
                    exception_handlers={404: _not_found, 405: _not_allowed}, lifespan=_lifespan(jobs))
    app.state.jobs = jobs
    app.state.start = {"robot": robot_to_dict(robot)} if robot is not None else H.catalogue_robot({"name": "puma560"})
    return app


def _routes() -> list[Route]:
    return [
        Route("/", _index),
        Route("/favicon.ico", lambda request: Response(status_code=204)),
        Route("/static/{name}", _static),
        Route("/katex/{name}", _katex),
        Route("/api/catalogue", lambda request: JSONResponse(H.catalogue())),
        Route("/api/catalogue/load", _post(H.catalogue_robot), methods=["POST"]),
        Route("/api/robot", _post(H.robot_info), methods=["POST"]),
        Route("/api/kinematics", _post(H.kinematics), methods=["POST"]),
        Route("/api/ik", _post(_ik.inverse_kinematics, threaded=True), methods=["POST"]),
        Route("/api/dynamics", _post(H.dynamics), methods=["POST"]),
        Route("/api/statics", _post(H.statics), methods=["POST"]),
        Route("/api/table", _post(H.table), methods=["POST"]),
        Route("/api/robot-file", _post(H.robot_file), methods=["POST"]),
        Route("/api/open", _post(H.opened_file, MAX_CHECK_BYTES), methods=["POST"]),
        Route("/api/jobs", _job_start, methods=["POST"]),
        Route("/api/jobs/{job}", _job_status),
        Route("/api/jobs/{job}/cancel", _job_cancel, methods=["POST"]),
    ]


async def _index(request: Request) -> Response:
    start = json.dumps(request.app.state.start)
    start = start.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")  # stays inside <script>
    return HTMLResponse(_asset("index.html").replace("$START", start), headers=_NO_FRAMES)


async def _static(request: Request) -> Response:
    name = request.path_params["name"]
    if name not in _STATIC:
        return _error(H.RequestError("no such file", 404))
    return Response(_asset(name), media_type=_STATIC[name])


async def _katex(request: Request) -> Response:
    """The report's bundled KaTeX (fonts inlined in the CSS)."""
    from ..report import katex_bundle

    css, js = katex_bundle()
    if request.path_params["name"] == "katex.css":
        return Response(css, media_type="text/css")
    if request.path_params["name"] == "katex.js":
        return Response(js, media_type="text/javascript")
    return _error(H.RequestError("no such file", 404))


async def _job_start(request: Request) -> Response:
    try:
        body = await _read_json(request, MAX_CHECK_BYTES)
        kind = body.get("kind") if isinstance(body, dict) else None
        payload = body.get("payload") if isinstance(body, dict) else None
        if not isinstance(payload, dict):
            raise H.RequestError("a job is {\"kind\": ..., \"payload\": {...}}", 422)
        if kind != "check":
            H.robot_of(payload)  # a bad table is refused here, with its cell, before a process starts
        slot = body.get("slot")
        if slot is not None and not (isinstance(slot, str) and 0 < len(slot) <= 64):
            raise H.RequestError("a job's \"slot\" is a string of at most 64 characters", 422)
        return JSONResponse(request.app.state.jobs.start(kind, payload, slot))
    except H.RequestError as exc:
        return _error(exc)


async def _job_status(request: Request) -> Response:
    try:
        return JSONResponse(request.app.state.jobs.status(request.path_params["job"]))
    except H.RequestError as exc:
        return _error(exc)


async def _job_cancel(request: Request) -> Response:
    try:
        return JSONResponse(request.app.state.jobs.cancel(request.path_params["job"]))
    except H.RequestError as exc:
        return _error(exc)


def _lifespan(jobs: Jobs) -> Callable:
    @contextlib.asynccontextmanager
    async def lifespan(app: Starlette):
        threading.Thread(target=jobs.warm_up, daemon=True).start()  # the first formula after a start is quick too
        yield
        jobs.shutdown()  # the server stops: no job outlives it

    return lifespan


_NO_FRAMES = {"X-Frame-Options": "DENY", "Content-Security-Policy": "frame-ancestors 'none'"}


async def _not_found(request: Request, exc: Exception) -> Response:
    return _error(H.RequestError(f"no such page: {request.url.path}", 404))


async def _not_allowed(request: Request, exc: Exception) -> Response:
    return _error(H.RequestError(f"{request.method} is not accepted at {request.url.path}", 405))
