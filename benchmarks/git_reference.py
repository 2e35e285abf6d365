"""A module of the package as a commit had it, for the benchmarks that time today's code against the code it replaced
in the same run (bench_board_plan.py, bench_board_detection.py), with no old copy kept in src/."""

import importlib.util
import re
import subprocess
import sys
import tempfile
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parents[1]
# modules renamed since (old name -> today's): an old file's imports of them are read as today's
RENAMED = {"poseintegrity.defaults": "poseintegrity.config", "poseintegrity.tables": "poseintegrity.table_checks",
           "poseintegrity.staging": "poseintegrity.atomic_write", "poseintegrity.timing": "poseintegrity.stage_timing",
           "poseintegrity.dispatch": "poseintegrity.kernel_pin", "poseintegrity.parallel": "poseintegrity.workers",
           "poseintegrity.protocol": "poseintegrity.params.protocol", "poseintegrity.worlds": "poseintegrity.world_order"}


def module_at(commit: str, path: str) -> ModuleType:
    """The file ``path`` (e.g. ``src/poseintegrity/scenes/board_plan.py``) at ``commit``, read from git and imported
    as a module of its own, ``<stem>_<commit>``; its imports of the package resolve to today's modules (renamed ones
    through :data:`RENAMED`)."""
    source = subprocess.run(["git", "-C", str(ROOT), "show", f"{commit}:{path}"], check=True, capture_output=True,
                            text=True).stdout
    for old, new in RENAMED.items():
        source = re.sub(rf"^from {re.escape(old)} import", f"from {new} import", source, flags=re.MULTILINE)
    name = f"{Path(path).stem}_{commit}"
    file = Path(tempfile.mkdtemp()) / f"{name}.py"
    file.write_text(source)
    spec = importlib.util.spec_from_file_location(name, file)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module
