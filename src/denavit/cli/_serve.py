"""denavit serve: the browser workbench on this machine (Starlette on uvicorn, the ``web`` extra)."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

from ..errors import ParseError
from ._common import bounded_int, load

if TYPE_CHECKING:
    import socket

#: Port used when --port is not given.
DEFAULT_PORT = 8765
_LOOPBACK = ("127.0.0.1", "localhost", "::1")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("serve", help="the browser workbench: edit a DH table, see the arm, derive, check (127.0.0.1)",
                       description="Serve the workbench page on this machine (loopback only unless --host) and print "
                                   "its address; Ctrl-C stops it.  Needs pip install \"denavit[web]\".")
    p.add_argument("robot", metavar="ROBOT", nargs="?", default=None,
                   help="built-in name or robot file to open with (default puma560)")
    p.add_argument("--port", type=bounded_int(0, 65535), default=DEFAULT_PORT,
                   help=f"TCP port (default {DEFAULT_PORT}; 0 picks a free one)")
    p.add_argument("--host", default=None, metavar="H",
                   help="address to listen on (default 127.0.0.1; any other is reachable from other machines)")
    p.add_argument("--open", action="store_true", help="open the page in the default web browser")
    p.add_argument("--json", action="store_true", help="print the address as JSON")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="override a robot parameter (repeatable)")
    p.set_defaults(handler=cmd_serve)


def _bind(host: str, port: int) -> socket.socket:
    """A listening socket, or one line saying why not (a port in use, an unknown address)."""
    # imported here, not at the top: only serve opens a socket (socket is 8 ms of every command's start-up)
    import errno
    import socket

    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError) as exc:
        raise ParseError(f"--host {host!r}: not an address of this machine ({exc})") from None
    family, _, proto, _, addr = infos[0]
    # proto IPPROTO_TCP, not 0: asyncio sets TCP_NODELAY on the accepted connections only then; without it each
    # answer on a kept-alive connection waits ~40 ms for the browser's delayed ACK (Nagle), 10x the work itself
    sock = socket.socket(family, socket.SOCK_STREAM, proto or socket.IPPROTO_TCP)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    try:
        sock.bind(addr)
        sock.listen(128)
    except OSError as exc:
        sock.close()
        if exc.errno == errno.EADDRINUSE:
            raise ParseError(f"port {port} on {host} is in use (another server?); choose another with --port") from None
        raise ParseError(f"cannot listen on {host} port {port}: {exc.strerror or exc}") from None
    return sock


def cmd_serve(args: argparse.Namespace):
    from ..web import create_app, require_web

    require_web()
    import uvicorn

    robot = load(args) if args.robot is not None else None
    host = args.host or "127.0.0.1"
    if args.host is not None and args.host not in _LOOPBACK:
        print(f"denavit serve: warning: listening on {host}: anyone who can reach this machine on port {args.port} "
              "can use the workbench (and its CPU)", file=sys.stderr)
    sock = _bind(host, args.port)
    port = sock.getsockname()[1]
    shown = f"[{host}]" if ":" in host else host
    url = f"http://{shown}:{port}/"
    hosts = ["*"] if host in ("0.0.0.0", "::") else sorted({shown, host, "127.0.0.1", "localhost", "[::1]"})
    app = create_app(robot, allowed_hosts=hosts)
    print(f"denavit workbench at {url}  (Ctrl-C stops it)", flush=True)
    if args.open:
        import threading
        import webbrowser

        threading.Timer(0.5, webbrowser.open, args=(url,)).start()
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="on"))
    try:
        server.run(sockets=[sock])
    finally:
        sock.close()
    return {"url": url, "robot": robot.name if robot is not None else "puma560"}, "workbench stopped"
