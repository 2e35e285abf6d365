"""Count the battery's outcomes by class: ``python tests/battery/census.py`` (prints one line per failure too)."""

import collections
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1] / "localization"))
sys.path.insert(0, str(Path(__file__).parents[1] / "recorded"))  # recorded_tools: the bag writer

from test_battery import CASES, outcome  # noqa: E402

counts = collections.Counter()
for name, argument, label in CASES:
    with tempfile.TemporaryDirectory() as tmp:
        result = outcome(name, argument, label, Path(tmp))
    counts[result] += 1
    if result not in {"refused", "flagged", "accepted"}:
        print(f"{result:<28} {name}:{argument}:{label}")
print(f"\n{len(CASES)} cases: " + ", ".join(f"{k} {v}" for k, v in counts.most_common()))
