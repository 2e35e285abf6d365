"""The common bad-input battery: its registry and bad values are modules of this folder."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1] / "localization"))
sys.path.insert(0, str(Path(__file__).parents[1] / "recorded"))  # recorded_tools: the bag writer
