"""The browser side's plumbing that needs no browser: ports and the viewer's address."""

from __future__ import annotations

import socket
import subprocess
import sys
import urllib.parse

import pytest

from tests.run.viewer.browser import ViewerCheckError, free_port, viewer_url, wait_for_port


def test_the_live_viewer_url_opens_the_grpc_proxy_with_webgl() -> None:
    url = viewer_url(9090, 9876)
    parsed = urllib.parse.urlparse(url)
    assert (parsed.scheme, parsed.netloc, parsed.path) == ("http", "127.0.0.1:9090", "/")
    query = urllib.parse.parse_qs(parsed.query)
    assert query == {"url": ["rerun+http://127.0.0.1:9876/proxy"], "renderer": ["webgl"]}


def test_waiting_for_a_port_returns_once_something_listens_and_reports_why_it_ended() -> None:
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        wait_for_port(server.getsockname()[1], 5.0)  # returns: it listens
    port = free_port()
    with pytest.raises(ViewerCheckError, match=f"nothing listened on port {port} within 1 s"):
        wait_for_port(port, 1.0)
    exited = subprocess.Popen([sys.executable, "-c", "raise SystemExit(4)"])
    exited.wait(timeout=60)
    with pytest.raises(ViewerCheckError, match="process exited with 4 before port"):
        wait_for_port(free_port(), 5.0, exited)
