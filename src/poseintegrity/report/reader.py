"""The metrics of a run read for the summary's tables: each value as the stage wrote it, rounded as shown, its
interval beside it, and "not run" / "not measured" where a stage or a key is absent. Nothing is computed here."""

from __future__ import annotations

from poseintegrity.report.lookup import MISSING, absent, lookup

SPL, SHARE, RATE = "{:.1f}", "{:.0%}", "{:.2%}"


class Reader:
    """The metrics of a run, read for the table: :meth:`text` shows one value as read, :meth:`value` gives it for a
    verdict (MISSING when absent)."""

    def __init__(self, metrics: dict[str, dict]):
        self.metrics = metrics

    def value(self, stage: str, key: str):
        return lookup(self.metrics, stage, key)

    def text(self, stage: str, key: str, fmt: str = SPL) -> str:
        value = lookup(self.metrics, stage, key)
        if value is MISSING:
            return absent(self.metrics, stage)
        if value is None:
            return "none"
        return fmt.format(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else str(value)

    def interval(self, stage: str, key: str, fmt: str = SPL) -> str:
        """An interval [low, high] as "[low, high]" (an end without an operating point: "none"); "" when absent."""
        value = lookup(self.metrics, stage, key)
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            return ""
        return "[" + ", ".join("none" if end is None else fmt.format(end) for end in value) + "]"

    def share(self, stage: str, *entries: str) -> str:
        """The predictor's share of the ceiling at each of ``entries`` (``<predictor>.<tolerance>``) with its interval,
        e.g. "22% [5%, 40%] of ceiling" or "9% [..] · 10% [..] of ceiling"; "ceiling share not measured" when the
        metrics hold none of them."""
        if all(self.value(stage, f"{entry}.ceiling_share") is MISSING for entry in entries):
            return "ceiling share " + absent(self.metrics, stage)
        return " · ".join(" ".join(filter(None, (self.text(stage, f"{entry}.ceiling_share", SHARE), self.interval(
            stage, f"{entry}.interval.ceiling_share", SHARE)))) for entry in entries) + " of ceiling"

    def gain(self, stage: str, key: str, unit: str = "deg") -> str:
        """A gain (``key``: ``<...>.gain``, and ``<...>.interval.gain`` beside it) as "+2.4 deg [-0.9, +5.1]"."""
        return " ".join(filter(None, (f"{self.text(stage, key, '{:+.1f}')} {unit}",
                                      self.interval(stage, key.rsplit('.', 1)[0] + ".interval.gain", "{:+.1f}"))))
