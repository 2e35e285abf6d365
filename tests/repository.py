"""What a clone of the repository can follow: the helper behind the tests that keep it self-contained."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MARKDOWN_NAME = re.compile(r"[\w./-]*\w\.md\b")
CLIMB = re.compile(r"(?:\.\./)+[\w.-]+")
MACHINE_PATH = re.compile(r"(?<![\w.:/])/(?:work|home|root|mnt)/[\w.-]+")


def outside_references(text: str, where: Path) -> list[str]:
    """Names in ``text`` (of a file in folder ``where``) that a clone of the repository cannot follow: a markdown
    file that exists neither beside it, nor from the root, nor under that name among the repository's documents; a
    relative path that climbs above the root; an absolute path of somebody's machine."""
    known = {p.name for folder in (ROOT, ROOT / "docs", ROOT / "src" / "poseintegrity" / "assets", ROOT / "reports") for p in folder.glob("*.md")}
    missing = [name for name in MARKDOWN_NAME.findall(text)
               if not ((where / name).exists() or (ROOT / name).exists() or Path(name).name in known)]
    climbing = [path for path in CLIMB.findall(text) if not (where / path).resolve().is_relative_to(ROOT)]
    return missing + climbing + MACHINE_PATH.findall(text)
