"""Rerun's web viewer in headless Chromium: serve a recording, open it, take a screenshot.

The recording is served the way a user would open it: ``rerun --serve-web``
(a file, :func:`serve_file`), or the gRPC server of a live ``headsim run
--serve`` (:func:`viewer_url`).  Chromium (Debian's ``chromium``) renders the
viewer with WebGL on SwiftShader (CPU; WebGPU fails there on a buffer-size
limit) and is driven through its DevTools protocol with the ``websockets``
package that rerun-sdk installs: navigate, wait until the viewer has drawn,
capture the page as PNG (:func:`screenshot`).
"""

from __future__ import annotations

import base64
import contextlib
import json
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time
import urllib.parse
import urllib.request
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from tests.run.viewer.judge import WINDOW, drawn

#: Chromium's flags: headless, no network beyond 127.0.0.1, WebGL through SwiftShader.
CHROMIUM_FLAGS = (
    "--headless=new",
    "--no-sandbox",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-default-apps",
    "--disable-extensions",
    "--mute-audio",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-gpu-sandbox",
)


#: Debian's package and executable names.
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome")


class ViewerCheckError(RuntimeError):
    """The viewer or the browser could not be started or did not draw in time."""


def chromium_path() -> str | None:
    """The Chromium executable on PATH, or None."""
    for name in CHROMIUM_NAMES:
        found = shutil.which(name)
        if found:
            return found
    return None


def free_port() -> int:
    """A TCP port on 127.0.0.1 that is free now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def wait_for_port(port: int, timeout_s: float, process: subprocess.Popen | None = None) -> None:
    """Wait until something listens on 127.0.0.1:port; raise after ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if process is not None and process.poll() is not None:
            raise ViewerCheckError(f"process exited with {process.returncode} before port {port}")
        with socket.socket() as s:
            s.settimeout(0.5)
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.2)
    raise ViewerCheckError(f"nothing listened on port {port} within {timeout_s:.0f} s")


def viewer_url(web_port: int, grpc_port: int) -> str:
    """The web viewer's address that opens the gRPC server's recording, with WebGL."""
    source = urllib.parse.quote(f"rerun+http://127.0.0.1:{grpc_port}/proxy", safe="")
    return f"http://127.0.0.1:{web_port}/?url={source}&renderer=webgl"


def rerun_executable() -> str:
    """The SDK's ``rerun`` binary (not its Python wrapper, whose child a terminate would
    leave running), else ``rerun`` on PATH."""
    try:
        import rerun_cli

        binary = Path(rerun_cli.__file__).parent / "rerun"
        if binary.exists():
            return str(binary)
    except ImportError:
        pass
    found = shutil.which("rerun")
    if found is None:
        raise ViewerCheckError("the rerun command is not installed (pip install rerun-sdk)")
    return found


@contextlib.contextmanager
def serve_file(rrd: Path, timeout_s: float = 60.0) -> Iterator[str]:
    """``rerun --serve-web`` on a file; yields the viewer's URL; stops the server after."""
    web_port, grpc_port = free_port(), free_port()
    command = [
        rerun_executable(),
        "--serve-web",
        "--web-viewer-port",
        str(web_port),
        "--port",
        str(grpc_port),
        str(rrd),
    ]
    with tempfile.TemporaryFile() as log:
        process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
        try:
            wait_for_port(web_port, timeout_s, process)
            wait_for_port(grpc_port, timeout_s, process)
            yield viewer_url(web_port, grpc_port)
        finally:
            _stop(process)


def _stop(process: subprocess.Popen, group: bool = False) -> None:
    """Terminate a child process (its whole process group when ``group``), kill it if it
    does not end within 10 s."""
    if group:
        _signal_group(process, signal.SIGTERM)
    elif process.poll() is None:
        process.terminate()
    try:
        process.wait(timeout=10)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait(timeout=10)
    if group:
        # Chromium's helpers (zygote, GPU, crashpad) can outlive the browser and keep
        # writing into the profile; end them all before the profile is removed.
        _signal_group(process, signal.SIGKILL)


def _signal_group(process: subprocess.Popen, sig: int) -> None:
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(process.pid, sig)


def _remove_profile(profile: tempfile.TemporaryDirectory) -> None:
    """Remove a browser profile; a helper still writing into it gets a few tries."""
    for _ in range(10):
        try:
            profile.cleanup()
            return
        except OSError:
            time.sleep(0.3)
    shutil.rmtree(profile.name, ignore_errors=True)


@dataclass
class Browser:
    """A headless Chromium with its DevTools endpoint."""

    process: subprocess.Popen
    port: int
    profile: tempfile.TemporaryDirectory

    def page_websocket(self, timeout_s: float = 30.0) -> str:
        """The DevTools WebSocket URL of the first page."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{self.port}/json/list") as r:
                    pages = [p for p in json.load(r) if p.get("type") == "page"]
                if pages:
                    return str(pages[0]["webSocketDebuggerUrl"])
            except OSError:
                pass
            time.sleep(0.3)
        raise ViewerCheckError(f"Chromium's DevTools did not answer within {timeout_s:.0f} s")


@contextlib.contextmanager
def chromium(executable: str | None = None, timeout_s: float = 60.0) -> Iterator[Browser]:
    """Start headless Chromium with a fresh profile; close it after."""
    executable = executable or chromium_path()
    if executable is None:
        raise ViewerCheckError(
            "Chromium is not installed (Debian/Ubuntu: apt-get install -y chromium)"
        )
    port = free_port()
    profile = tempfile.TemporaryDirectory(prefix="headsim-chromium-")
    command = [
        executable,
        *CHROMIUM_FLAGS,
        f"--user-data-dir={profile.name}",
        f"--remote-debugging-port={port}",
        f"--window-size={WINDOW[0]},{WINDOW[1]}",
        "about:blank",
    ]
    with tempfile.TemporaryFile() as log:
        process = subprocess.Popen(
            command, stdout=log, stderr=subprocess.STDOUT, start_new_session=True
        )
        try:
            wait_for_port(port, timeout_s, process)
            yield Browser(process, port, profile)
        finally:
            _stop(process, group=True)
            _remove_profile(profile)


class _DevTools:
    """A minimal DevTools protocol client over one WebSocket."""

    def __init__(self, url: str) -> None:
        from websockets.sync.client import connect

        self._connection = connect(url, max_size=64 * 2**20, open_timeout=30)
        self.socket = self._connection.__enter__()
        self.next_id = 0

    def call(self, method: str, timeout_s: float = 60.0, **params: object) -> dict:
        self.next_id += 1
        self.socket.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            message = json.loads(self.socket.recv(timeout=max(0.1, deadline - time.monotonic())))
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise ViewerCheckError(f"{method}: {message['error']}")
                return dict(message.get("result", {}))
        raise ViewerCheckError(f"{method}: no answer within {timeout_s:.0f} s")

    def close(self) -> None:
        self._connection.__exit__(None, None, None)


def screenshot(
    url: str,
    *,
    settle_s: float = 20.0,
    timeout_s: float = 240.0,
    ready: Callable[[np.ndarray], bool] | None = None,
    executable: str | None = None,
) -> np.ndarray:
    """Open ``url`` in headless Chromium and return the page as an RGB image (H, W, 3).

    Screenshots are taken every few seconds after ``settle_s``; the first one
    for which ``ready(image)`` is true is returned (default: the page stopped
    changing between two shots), else the last one when ``timeout_s`` ran out.
    """
    ready = ready or (lambda image: False)
    with chromium(executable) as browser:
        devtools = _DevTools(browser.page_websocket())
        try:
            devtools.call("Page.enable")
            devtools.call(
                "Emulation.setDeviceMetricsOverride",
                width=WINDOW[0],
                height=WINDOW[1],
                deviceScaleFactor=1,
                mobile=False,
            )
            devtools.call("Page.navigate", url=url)
            start = time.monotonic()
            time.sleep(settle_s)
            previous: np.ndarray | None = None
            image = _capture(devtools)
            while time.monotonic() - start < timeout_s:
                if ready(image):
                    break
                if previous is not None and np.array_equal(previous, image) and drawn(image):
                    break
                time.sleep(4.0)
                previous, image = image, _capture(devtools)
            return image
        finally:
            devtools.close()


def _capture(devtools: _DevTools) -> np.ndarray:
    # SwiftShader draws on the CPU: on two busy cores a capture has taken over a minute.
    data = devtools.call("Page.captureScreenshot", timeout_s=300.0, format="png")["data"]
    image = cv2.imdecode(np.frombuffer(base64.b64decode(data), np.uint8), cv2.IMREAD_COLOR)
    if image is None:
        raise ViewerCheckError("Chromium returned a screenshot that is not a PNG")
    return cv2.cvtColor(image, cv2.COLOR_BGR2RGB)
