"""Rerun's command-line conventions for every command that records.

``--rrd FILE`` writes a file; ``--connect`` (with ``--url``) streams to a
running viewer; ``--serve`` hosts a gRPC server and a web viewer for it.
The names and meanings are those of ``rerun.script_add_args`` (Rerun's
examples); its ``--save``/``--stdout``/``--headless`` are left out (``--rrd``
is headsim's ``--save``, and headsim never spawns a native viewer).  This
module imports no Rerun, so that ``headsim --help`` stays fast.

    parser = argparse.ArgumentParser()
    add_recording_arguments(parser)
    target = recording_target(parser.parse_args())   # RecordingTarget
"""

from __future__ import annotations

import argparse
import socket
import time
import urllib.parse
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from headsim.errors import BadInput, EnvironmentProblem

#: Rerun's default ports: the gRPC server and the web viewer.
DEFAULT_GRPC_PORT = 9876
DEFAULT_WEB_PORT = 9090
#: Where ``--connect`` streams without ``--url`` (a viewer started with ``rerun``).
DEFAULT_URL = f"rerun+http://127.0.0.1:{DEFAULT_GRPC_PORT}/proxy"
#: How long ``--connect`` waits for its viewer (to accept the connection, then each flush)
#: before the run gives up with exit 3: Rerun's own stream would wait for ever.
VIEWER_WAIT_S = 5.0
#: The same when the run was interrupted (Ctrl-C, SIGTERM) and the recording is closed.
INTERRUPTED_VIEWER_WAIT_S = 0.5
#: A flush to a viewer waits in slices this long, so that Ctrl-C and SIGTERM (handled by
#: Python between them, never inside Rerun's wait) end the run at once.
FLUSH_SLICE_S = 0.25


class RecordingArgumentError(BadInput, ValueError):
    """A recording option is invalid: ``field`` names it, ``allowed`` says what is."""

    def __init__(self, field: str, message: str, allowed: str) -> None:
        super().__init__(f"{field}: {message} (allowed: {allowed})")
        self.field, self.message, self.allowed = field, message, allowed


class ViewerUnreachable(EnvironmentProblem):
    """No Rerun viewer answered at ``--connect``'s address in time (exit 3)."""

    def __init__(self, url: str, wait_s: float, *, lost: bool = False) -> None:
        where = urllib.parse.urlparse(url).netloc or url
        if lost:
            message = f"the Rerun viewer at {where} did not take the recording within {wait_s:g} s"
        else:
            message = f"no Rerun viewer answered at {where} within {wait_s:g} s"
        super().__init__(f"{message}: start one with `rerun`, or use --rrd FILE")
        self.url, self.wait_s = url, wait_s


def check_viewer(url: str, wait_s: float = VIEWER_WAIT_S) -> None:
    """:class:`ViewerUnreachable` unless something accepts a connection at ``url``'s host and
    port within ``wait_s`` (tried again every 0.2 s: a viewer may be starting).

    Rerun's gRPC sink offers no such check: with nobody listening it retries for ever and its
    flush blocks (also Ctrl-C).  A URL without a port is left to :class:`Recorder`'s bounded
    flushes.
    """
    parsed = urllib.parse.urlparse(url)
    if parsed.hostname is None or parsed.port is None:
        return
    deadline = time.monotonic() + wait_s
    while True:
        left = deadline - time.monotonic()
        try:
            with socket.create_connection((parsed.hostname, parsed.port), timeout=max(left, 0.1)):
                return
        except OSError:
            if left <= 0:
                raise ViewerUnreachable(url, wait_s) from None
            time.sleep(min(0.2, max(left, 0.0)))


def flush_to_viewer(rec: Any, url: str, wait_s: float = VIEWER_WAIT_S) -> None:
    """Flush ``rec`` (a ``rerun.RecordingStream`` with a viewer among its sinks) within
    ``wait_s``, in slices; :class:`ViewerUnreachable` if the viewer does not take it (Rerun's
    own flush waits for ever on a viewer that is gone or does not answer)."""
    deadline = time.monotonic() + wait_s
    while True:
        try:
            rec.flush(timeout_sec=FLUSH_SLICE_S)
            return
        except RuntimeError as err:
            text = str(err).lower()
            # Rerun's words for "not yet": a timed-out wait, a viewer not (yet) connected.
            if "timed out" not in text and "unable to connect" not in text:
                raise
            if time.monotonic() >= deadline:
                raise ViewerUnreachable(url, wait_s, lost=True) from None


class _ViewerStreams:
    """Streams to a viewer (``--connect``) opened in this process and not closed cleanly."""

    open = 0


def viewer_stream_opened() -> None:
    """Note a stream to a viewer opened (:class:`headsim.runs.recording.Recorder`)."""
    _ViewerStreams.open += 1


def viewer_stream_closed() -> None:
    """Note a stream to a viewer closed cleanly (it disconnected)."""
    _ViewerStreams.open -= 1


def viewer_streams_left_open() -> bool:
    """Whether a stream to a viewer was left open: Rerun's gRPC client then blocks the
    interpreter's exit, signals included, while its viewer does not answer."""
    return _ViewerStreams.open > 0


def job_target(target: RecordingTarget, job_id: str) -> RecordingTarget:
    """One sweep job's target: its own file ``DIR/JOB_ID.rrd``, the same viewer."""
    rrd = target.rrd / f"{job_id}.rrd" if target.rrd is not None else None
    return RecordingTarget(rrd=rrd, connect_url=target.connect_url)


@dataclass(frozen=True)
class RecordingTarget:
    """Where a recording goes: a file, a running viewer, a served web viewer (any of them)."""

    rrd: Path | None = None
    connect_url: str | None = None
    serve: bool = False
    grpc_port: int = DEFAULT_GRPC_PORT
    web_port: int = DEFAULT_WEB_PORT

    @property
    def wanted(self) -> bool:
        """Whether anything is to be recorded."""
        return self.rrd is not None or self.connect_url is not None or self.serve

    @property
    def server_url(self) -> str:
        """The gRPC address of ``--serve``'s server, as a viewer opens it."""
        return f"rerun+http://127.0.0.1:{self.grpc_port}/proxy"

    @property
    def web_viewer_url(self) -> str:
        """The address of ``--serve``'s web viewer, opening this run."""
        source = urllib.parse.quote(self.server_url, safe="")
        return f"http://127.0.0.1:{self.web_port}/?url={source}"


def add_recording_arguments(parser: argparse.ArgumentParser, *, per_job: bool = False) -> None:
    """Add ``--rrd``, ``--connect``, ``--url``, ``--serve`` and the two ports to ``parser``.

    ``per_job``: for a command of many runs (``sweep``): ``--rrd DIR`` holds one file
    per job, ``--connect`` streams each job as its own recording, and there is no
    ``--serve`` (parallel jobs cannot share one server's port).
    """
    group = parser.add_argument_group("recording (Rerun)")
    if per_job:
        group.add_argument(
            "--rrd", metavar="DIR", help="record each job to DIR/JOB_ID.rrd (created)"
        )
        group.add_argument(
            "--connect",
            action="store_true",
            help="stream each job live to a running Rerun viewer, one recording per job",
        )
        group.add_argument(
            "--url", metavar="URL", help=f"the viewer --connect streams to (default {DEFAULT_URL})"
        )
        return
    group.add_argument("--rrd", metavar="FILE", help="record the run to this Rerun .rrd file")
    group.add_argument(
        "--connect",
        action="store_true",
        help="stream the recording live to a running Rerun viewer (start one with `rerun`)",
    )
    group.add_argument(
        "--url",
        metavar="URL",
        help=f"the viewer --connect streams to (default {DEFAULT_URL})",
    )
    group.add_argument(
        "--serve",
        action="store_true",
        help="host the recording live in a web viewer (the URL is printed); after the run "
        "it is served until Ctrl-C",
    )
    group.add_argument(
        "--web-port",
        type=int,
        default=DEFAULT_WEB_PORT,
        metavar="PORT",
        help=f"--serve: the web viewer's port (default {DEFAULT_WEB_PORT})",
    )
    group.add_argument(
        "--grpc-port",
        type=int,
        default=DEFAULT_GRPC_PORT,
        metavar="PORT",
        help=f"--serve: the gRPC server's port (default {DEFAULT_GRPC_PORT})",
    )


def recording_target(args: argparse.Namespace, *, per_job: bool = False) -> RecordingTarget:
    """The checked target of parsed recording options; :class:`RecordingArgumentError` if bad.

    ``per_job``: ``rrd`` is a directory (see :func:`add_recording_arguments`).
    """
    rrd = Path(args.rrd) if getattr(args, "rrd", None) else None
    if per_job and rrd is not None and rrd.exists() and not rrd.is_dir():
        raise RecordingArgumentError("--rrd", f"{rrd} is not a directory", "a directory")
    if not per_job and rrd is not None and rrd.is_dir():
        raise RecordingArgumentError("--rrd", f"{rrd} is a directory", "a file path, e.g. run.rrd")
    url = getattr(args, "url", None)
    connect = bool(getattr(args, "connect", False))
    if url is not None and not connect:
        raise RecordingArgumentError("--url", "given without --connect", "--connect --url URL")
    if url is not None:
        parsed = urllib.parse.urlparse(url)
        if parsed.scheme not in ("rerun", "rerun+http", "rerun+https") or not parsed.path.endswith(
            "/proxy"
        ):
            raise RecordingArgumentError(
                "--url", f"{url!r} is not a Rerun gRPC address", "e.g. " + DEFAULT_URL
            )
    ports = {
        "--web-port": getattr(args, "web_port", DEFAULT_WEB_PORT),
        "--grpc-port": getattr(args, "grpc_port", DEFAULT_GRPC_PORT),
    }
    for field, port in ports.items():
        if not 1 <= port <= 65535:
            raise RecordingArgumentError(field, f"{port} is not a port", "1 to 65535")
    if ports["--web-port"] == ports["--grpc-port"]:
        raise RecordingArgumentError(
            "--web-port", "is the same as --grpc-port", "two different ports"
        )
    return RecordingTarget(
        rrd=rrd,
        connect_url=(url or DEFAULT_URL) if connect else None,
        serve=bool(getattr(args, "serve", False)),
        grpc_port=ports["--grpc-port"],
        web_port=ports["--web-port"],
    )


__all__ = [
    "DEFAULT_URL",
    "INTERRUPTED_VIEWER_WAIT_S",
    "VIEWER_WAIT_S",
    "RecordingArgumentError",
    "RecordingTarget",
    "ViewerUnreachable",
    "add_recording_arguments",
    "check_viewer",
    "flush_to_viewer",
    "job_target",
    "recording_target",
    "viewer_stream_closed",
    "viewer_stream_opened",
    "viewer_streams_left_open",
]
