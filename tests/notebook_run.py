"""Running the pipeline notebooks as a person does in JupyterLab, for the notebook tests.

:class:`NotebookServer` starts JupyterLab as the README says (``.venv/bin/jupyter lab``, without a browser) on a
loopback port in a project (a copy on the tiny parameters, tests/project_copy.py). :meth:`NotebookServer.run` opens
a notebook as JupyterLab's page does, through the server's REST API: it reads the notebook (contents), starts a
session for it (the server starts the kernel in the notebook's own folder, ``notebooks/``), then sends every code
cell over the kernel's websocket channels with JupyterLab's protocol (``v1.kernel.websocket.jupyter.org``), one
after the other as "Run All Cells" does. No parameters are injected: the notebook runs as it is saved. A cell that
errs fails the run, naming the notebook, the cell and the error.
"""

from __future__ import annotations

import json
import os
import re
import secrets
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request
import uuid
from pathlib import Path

import websocket  # websocket-client, a dependency of jupyter_server
from jupyter_server.services.kernels.connection.base import deserialize_msg_from_ws_v1, serialize_msg_to_ws_v1

from poseintegrity.kernel_pin import pinned_environment
from repository import ROOT

TINY_PARAMS = ROOT / "tests" / "params_tiny.yaml"
JUPYTER = Path(sys.executable).parent / "jupyter"  # the venv's, as the README's `.venv/bin/jupyter lab`
PROTOCOL = "v1.kernel.websocket.jupyter.org"  # what JupyterLab asks the server for
ANSI = re.compile(r"\x1b\[[0-9;]*m")
UNPINNED = "loaded before poseintegrity"  # poseintegrity.kernel_pin's warning


class NotebookServer:
    """``jupyter lab --no-browser`` in ``root`` on 127.0.0.1 (a free port, a token of its own), with the venv's
    ``python3`` kernel first on JUPYTER_PATH and a configuration and runtime folder of its own (none of the user's);
    a context manager that stops it. Its environment is the test process's without the CPU dispatch settings that
    importing poseintegrity put there (a user's shell has none), so each notebook must pin them itself, as in
    JupyterLab. The test session's MPLBACKEND=Agg (conftest.py) stays: figures are saved, not also drawn into the
    notebook."""

    def __init__(self, root: Path, start_timeout_s: float = 120.0):
        self.root, self.start_timeout_s = Path(root), start_timeout_s

    def __enter__(self) -> NotebookServer:
        self.home = Path(tempfile.mkdtemp(prefix="jupyter-"))
        env = {key: value for key, value in os.environ.items() if key not in pinned_environment(frozenset())}
        env |= {"JUPYTER_CONFIG_DIR": str(self.home / "config"),
               "JUPYTER_RUNTIME_DIR": str(self.home / "runtime"),
               "JUPYTER_PATH": str(Path(sys.prefix) / "share" / "jupyter")}  # the kernelspec `make install` wrote
        self.token = secrets.token_hex(16)
        self.log = open(self.home / "server.log", "w")
        self.process = subprocess.Popen(
            [str(JUPYTER), "lab", "--no-browser", "--allow-root", "--ServerApp.ip=127.0.0.1", "--ServerApp.port=0",
             f"--ServerApp.root_dir={self.root}", f"--IdentityProvider.token={self.token}"],
            env=env, stdout=self.log, stderr=subprocess.STDOUT)
        try:
            self._started_url()
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def _started_url(self) -> str:
        """The server's base URL, from the file it writes into its runtime folder (with the port it chose), once
        its API answers (the file comes just before the server listens)."""
        deadline = time.monotonic() + self.start_timeout_s
        info = self.home / "runtime" / f"jpserver-{self.process.pid}.json"
        while True:
            assert self.process.poll() is None, f"jupyter lab exited ({self.process.returncode}):\n{self.output()}"
            assert time.monotonic() < deadline, f"jupyter lab did not start in {self.start_timeout_s} s:\n" \
                                                f"{self.output()}"
            if info.is_file():
                self.url = json.loads(info.read_text())["url"].rstrip("/")
                try:
                    self.request("GET", "/api/status")
                    return self.url
                except urllib.error.URLError:
                    pass
            time.sleep(0.1)

    def output(self) -> str:
        self.log.flush()
        return (self.home / "server.log").read_text()[-4000:]

    def __exit__(self, *exc) -> None:
        self.process.terminate()
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self.log.close()
        shutil.rmtree(self.home, ignore_errors=True)

    def request(self, method: str, path: str, body: dict | None = None) -> dict | None:
        """A REST call of the server's API (``/api/...``); its JSON answer."""
        request = urllib.request.Request(f"{self.url}{path}", method=method,
                                         data=None if body is None else json.dumps(body).encode(),
                                         headers={"Authorization": f"token {self.token}",
                                                  "Content-Type": "application/json"})
        with urllib.request.urlopen(request, timeout=120) as answer:
            text = answer.read()
        return json.loads(text) if text else None

    def run(self, notebook: str, cell_timeout_s: float = 900.0) -> dict:
        """Open ``notebook`` (a path under the root, e.g. ``notebooks/03_fit_artifact_models.ipynb``) and run every
        code cell in order in its own kernel, which is shut down afterwards; returns the notebook as the server
        read it. AssertionError naming the cell and its error when one errs, when the kernel did not start in the
        notebook's folder, or when a library loaded before poseintegrity could pin its CPU dispatch (dispatch.py:
        the numbers would then differ from the pipeline's in the last bits)."""
        model = self.request("GET", f"/api/contents/{notebook}?content=1&type=notebook")
        session = self.request("POST", "/api/sessions", {"path": notebook, "name": Path(notebook).name,
                                                         "type": "notebook", "kernel": {"name": "python3"}})
        try:
            channels = KernelChannels(self.url.replace("http", "ws", 1), session, self.token)
            try:
                channels.kernel_info()
                cwd = channels.execute("", cell_timeout_s, cwd="__import__('os').getcwd()")["cwd"]
                folder = str((self.root / notebook).parent)
                assert cwd == folder, f"{notebook}: the kernel started in {cwd}, not in the notebook's folder {folder}"
                for cell in model["content"]["cells"]:
                    if cell["cell_type"] == "code":
                        channels.execute(cell["source"], cell_timeout_s, where=f"{notebook}: cell {cell.get('id')}")
                assert UNPINNED not in channels.stderr, f"{notebook}: {channels.stderr[:2000]}"
            finally:
                channels.close()
        finally:
            self.request("DELETE", f"/api/sessions/{session['id']}")
        return model["content"]


class KernelChannels:
    """The websocket of a session's kernel (``/api/kernels/<id>/channels``), spoken as JupyterLab does."""

    def __init__(self, ws_url: str, session: dict, token: str):
        self.session_id, self.stderr = session["id"], ""  # everything the kernel wrote to stderr
        self.ws = websocket.create_connection(
            f"{ws_url}/api/kernels/{session['kernel']['id']}/channels?session_id={self.session_id}",
            header=[f"Authorization: token {token}"], subprotocols=[PROTOCOL], timeout=60)
        assert self.ws.subprotocol == PROTOCOL, f"the server did not speak {PROTOCOL}: {self.ws.subprotocol}"

    def close(self) -> None:
        self.ws.close()

    def send(self, msg_type: str, content: dict) -> str:
        msg_id = uuid.uuid4().hex
        header = {"msg_id": msg_id, "msg_type": msg_type, "session": self.session_id, "username": "test",
                  "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "version": "5.4"}
        message = {"header": header, "parent_header": {}, "metadata": {}, "content": content}
        self.ws.send_binary(serialize_msg_to_ws_v1(message, "shell", lambda part: json.dumps(part).encode()))
        return msg_id

    def replies(self, msg_id: str, timeout_s: float):
        """(channel, msg_type, content) of every message answering ``msg_id``, until its reply has come on shell
        and the kernel has gone idle on iopub."""
        deadline, replied, idle = time.monotonic() + timeout_s, False, False
        while not (replied and idle):
            self.ws.settimeout(max(deadline - time.monotonic(), 0.1))
            try:
                frame = self.ws.recv()
            except websocket.WebSocketTimeoutException:
                raise AssertionError(f"no answer to {msg_id} within {timeout_s} s") from None
            channel, parts = deserialize_msg_from_ws_v1(frame)
            header, parent, _, content = (json.loads(part) for part in parts[:4])
            if parent.get("msg_id") != msg_id:
                continue
            replied |= channel == "shell"
            idle |= channel == "iopub" and header["msg_type"] == "status" and content["execution_state"] == "idle"
            yield channel, header["msg_type"], content

    def kernel_info(self) -> None:
        """JupyterLab's first request: once answered, the kernel is up and its iopub channel reaches us."""
        for _ in self.replies(self.send("kernel_info_request", {}), 120):
            pass

    def execute(self, code: str, timeout_s: float, where: str = "", **expressions: str) -> dict:
        """Run ``code`` as a cell; the values of ``expressions`` (name -> Python expression) as text.
        AssertionError naming ``where`` and the error when it errs."""
        msg_id = self.send("execute_request", {"code": code, "silent": not where, "store_history": bool(where),
                                               "user_expressions": expressions, "allow_stdin": False,
                                               "stop_on_error": True})
        for channel, msg_type, content in self.replies(msg_id, timeout_s):
            if channel == "shell":
                reply = content
            elif msg_type == "stream" and content["name"] == "stderr":
                self.stderr += content["text"]
            elif msg_type == "error":  # iopub: the traceback JupyterLab shows under the cell
                raise AssertionError(f"{where}: {content['ename']}: {content['evalue']}\n"
                                     + ANSI.sub("", "\n".join(content["traceback"]))[-4000:])
        assert reply["status"] == "ok", f"{where}: {reply['status']}: {reply.get('ename')}: {reply.get('evalue')}"
        return {name: value["data"]["text/plain"].strip("'") for name, value in reply["user_expressions"].items()}
