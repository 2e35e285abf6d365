"""A screenshot of JupyterLab with a pipeline notebook opened and run, as a user sees it (issue 42).

    .venv/bin/python tools/jupyterlab_screenshot.py PROJECT [--notebook notebooks/03_fit_artifact_models.ipynb]
                                                    [--out jupyterlab.png]

PROJECT is a project whose data exist (after `make repro`, or a copy on the tiny parameters). The script starts
``jupyter lab`` there on a loopback port, then headless Chromium (Debian's package, ``chromium``) with a new, empty
profile, and drives it over the DevTools protocol: it opens the notebook in JupyterLab, runs "Run All Cells" (the
kernel starts in the notebook's folder, as for a user), waits until the kernel is idle, scrolls to the first figure
and saves the window as a PNG. It exits with status 1, naming the cells, if a cell erred. JupyterLab runs with
settings of its own (a temporary folder): autosave off, so that the source notebook stays output-free, and no news
or update check. Both processes are stopped at the end.
"""

from __future__ import annotations

import argparse
import base64
import json
import os
import secrets
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request
from contextlib import ExitStack, contextmanager
from pathlib import Path

import websocket  # websocket-client, a dependency of jupyter_server

JUPYTER = Path(sys.executable).parent / "jupyter"
CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync")
# JupyterLab user settings (plugin id -> values), each checked against the plugin's schema by the tests
LAB_SETTINGS = {
    "@jupyterlab/docmanager-extension:plugin": {"autosave": False},  # the run's outputs never reach the notebook
    "@jupyterlab/apputils-extension:notification": {"fetchNews": "false", "checkForUpdates": False},
}
# JavaScript evaluated in the page; window.jupyterapp exists with LabApp.expose_app_in_browser
NOTEBOOK = """(window.jupyterapp && Array.from(window.jupyterapp.shell.widgets("main"))
                                      .find(w => w.content && w.sessionContext))"""
KERNEL_IDLE = f"""(() => {{ const w = {NOTEBOOK}; const kernel = w && w.sessionContext && w.sessionContext.session
    && w.sessionContext.session.kernel;
    return !!(kernel && kernel.status === "idle" && w.content.widgets.length); }})()"""
RUN_ALL = f"""(() => {{ window.jupyterapp.shell.activateById({NOTEBOOK}.id);  // the command acts on the current one
    return window.jupyterapp.commands.execute("notebook:run-all-cells"); }})().then(() => true)"""
CELL_ERRORS = f"""(() => {{ const w = {NOTEBOOK}; return w.content.widgets.flatMap(cell => cell.model.type !== "code"
    ? [] : cell.model.toJSON().outputs.filter(o => o.output_type === "error")
                                    .map(o => `cell ${{cell.model.id}}: ${{o.ename}}: ${{o.evalue}}`)); }})()"""
SHOW_FIRST_FIGURE = f"""(() => {{ const w = {NOTEBOOK}; const cells = w.content.widgets;
    const i = cells.findIndex(c => c.model.type === "code"
                                   && c.model.toJSON().outputs.some(o => o.data && o.data["image/png"]));
    if (i >= 0) {{ w.content.activeCellIndex = i; cells[i].node.scrollIntoView({{block: "start"}}); }}
    return i; }})()"""


def write_lab_settings(folder: Path) -> Path:
    """``folder`` as a JupyterLab settings folder (JUPYTERLAB_SETTINGS_DIR) holding :data:`LAB_SETTINGS`."""
    for plugin, values in LAB_SETTINGS.items():
        package, name = plugin.split(":")
        path = folder / package / f"{name}.jupyterlab-settings"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(values))
    return folder


def lab_command(project: Path, token: str) -> list[str]:
    """``jupyter lab`` of this venv serving ``project`` on 127.0.0.1 (a port of the system's choice), with the
    application object in the page for the DevTools protocol to drive."""
    return [str(JUPYTER), "lab", "--no-browser", "--allow-root", "--ServerApp.ip=127.0.0.1", "--ServerApp.port=0",
            f"--ServerApp.root_dir={project}", f"--IdentityProvider.token={token}",
            "--LabApp.expose_app_in_browser=True"]


def chromium_command(browser: str, profile: Path, width: int, height: int) -> list[str]:
    """Headless Chromium with a new, empty profile, its DevTools port chosen by the system (written to
    ``profile / "DevToolsActivePort"``)."""
    return [browser, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", "--remote-debugging-port=0",
            f"--window-size={width},{height}", "about:blank"]


def wait_for(condition, what: str, timeout_s: float, process: subprocess.Popen | None = None):
    """Poll ``condition()`` until it returns something true; returns it. RuntimeError naming ``what`` on timeout or
    when ``process`` exits meanwhile."""
    deadline = time.monotonic() + timeout_s
    while True:
        if process is not None and process.poll() is not None:
            raise RuntimeError(f"{what}: the process exited ({process.returncode})")
        try:
            if found := condition():
                return found
        except OSError:  # not listening yet
            pass
        if time.monotonic() > deadline:
            raise RuntimeError(f"{what}: not within {timeout_s:.0f} s")
        time.sleep(0.25)


def devtools_port(profile: Path) -> int | None:
    """The DevTools port Chromium wrote into its profile (first line of DevToolsActivePort), or None yet."""
    path = profile / "DevToolsActivePort"
    lines = path.read_text().splitlines() if path.is_file() else []
    return int(lines[0]) if lines and lines[0].isdigit() else None


@contextmanager
def started(argv: list[str], env: dict[str, str], log: Path):
    """``argv`` running (output into ``log``) while the block runs; terminated (killed after 20 s) after it."""
    with open(log, "w") as output:
        process = subprocess.Popen(argv, env=env, stdout=output, stderr=subprocess.STDOUT)
        try:
            yield process
        finally:
            process.terminate()
            try:
                process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


class Page:
    """One page of Chromium over the DevTools protocol (Page, Runtime, Emulation domains)."""

    def __init__(self, port: int):
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as answer:
            target = next(t for t in json.load(answer) if t["type"] == "page")
        # no Origin header: Chromium refuses DevTools connections from origins it was not told to allow
        self.ws = websocket.create_connection(target["webSocketDebuggerUrl"], timeout=120, suppress_origin=True)
        self.calls = 0

    def call(self, method: str, **params):
        self.calls += 1
        self.ws.send(json.dumps({"id": self.calls, "method": method, "params": params}))
        while True:
            answer = json.loads(self.ws.recv())
            if answer.get("id") == self.calls:
                if "error" in answer:
                    raise RuntimeError(f"{method}: {answer['error']}")
                return answer["result"]

    def evaluate(self, expression: str):
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression[:60]}...: {result['exceptionDetails']}")
        return result["result"].get("value")


def screenshot(project: Path, notebook: str, out: Path, browser: str, width: int = 1440, height: int = 1000,
               timeout_s: float = 1800) -> list[str]:
    """Open ``notebook`` (relative to ``project``) in JupyterLab in ``browser``, run all its cells, save the window
    to ``out``; return the cells that erred (``cell <id>: <error>``)."""
    with ExitStack() as stack:
        home = Path(tempfile.mkdtemp(prefix="jupyterlab-screenshot-"))
        stack.callback(shutil.rmtree, home, ignore_errors=True)
        token = secrets.token_hex(16)
        env = {**os.environ, "JUPYTER_CONFIG_DIR": str(home / "config"), "JUPYTER_RUNTIME_DIR": str(home / "runtime"),
               "JUPYTERLAB_SETTINGS_DIR": str(write_lab_settings(home / "settings")),
               "JUPYTERLAB_WORKSPACES_DIR": str(home / "workspaces"),
               "JUPYTER_PATH": os.pathsep.join(filter(None, [str(Path(sys.prefix) / "share" / "jupyter"),
                                                             os.environ.get("JUPYTER_PATH")]))}
        lab = stack.enter_context(started(lab_command(project, token), env, home / "lab.log"))
        info = home / "runtime" / f"jpserver-{lab.pid}.json"
        url = wait_for(lambda: info.is_file() and json.loads(info.read_text())["url"].rstrip("/"), "jupyter lab", 120,
                       lab)
        wait_for(lambda: urllib.request.urlopen(f"{url}/api/status?token={token}", timeout=5), "jupyter lab's API", 60,
                 lab)
        profile = home / "chromium-profile"  # new and empty
        chromium = stack.enter_context(started(chromium_command(browser, profile, width, height), env,
                                               home / "chromium.log"))
        page = Page(wait_for(lambda: devtools_port(profile), "chromium's DevTools port", 60, chromium))
        stack.callback(page.ws.close)
        page.call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=False)
        page.call("Emulation.setFocusEmulationEnabled", enabled=True)  # headless: the page has focus, as a user's
        page.call("Page.navigate", url=f"{url}/lab/tree/{notebook}?token={token}")
        wait_for(lambda: page.evaluate(KERNEL_IDLE), f"{notebook} open with its kernel idle", 300, lab)
        page.evaluate(RUN_ALL)
        wait_for(lambda: page.evaluate(KERNEL_IDLE), f"{notebook} run", timeout_s, lab)
        errors = page.evaluate(CELL_ERRORS)
        page.evaluate(SHOW_FIRST_FIGURE)
        time.sleep(2)  # the figure drawn and the scroll settled
        out.write_bytes(base64.b64decode(page.call("Page.captureScreenshot", format="png")["data"]))
        return errors


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("project", type=Path, help="a project whose data exist (after make repro)")
    parser.add_argument("--notebook", default="notebooks/03_fit_artifact_models.ipynb", help="relative to project")
    parser.add_argument("--out", type=Path, default=Path("jupyterlab.png"), help="the PNG written")
    parser.add_argument("--browser", default="chromium", help="Chromium's command (Debian: apt-get install chromium)")
    args = parser.parse_args(argv)
    project = args.project.resolve()
    if not (project / "dvc.yaml").is_file() or not (project / args.notebook).is_file():
        sys.exit(f"{project}: no dvc.yaml or no {args.notebook} there: give the folder of a project")
    if shutil.which(args.browser) is None:
        sys.exit(f"{args.browser}: not found (Debian: apt-get install chromium)")
    errors = screenshot(project, args.notebook, args.out, args.browser)
    print(f"{args.out}: JupyterLab with {args.notebook} run")
    if errors:
        sys.exit("cells that erred:\n" + "\n".join(errors))


if __name__ == "__main__":
    main()
