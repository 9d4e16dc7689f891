"""Errors of the message adapters: each names the diagnostics reason key it stands for."""

from __future__ import annotations

#: every reason a patch can be dropped for (docs/guide_node.md, /diagnostics);
#: ``derailment``: in profiles mode, a pose past the flange or off the rail head
REJECTION_REASONS = (
    "nonfinite", "negative_pressure", "irregular_grid", "missing_field", "wrong_frame",
    "old_stamp", "no_kinematics", "stale_kinematics", "standstill", "too_large",
    "degenerate", "out_of_table", "derailment", "implausible",
)


class AdapterError(Exception):
    """Base of the adapters' errors."""


class RejectedInput(AdapterError):
    """An input that is dropped for this cycle; ``reason`` is a key of REJECTION_REASONS."""

    def __init__(self, reason: str, detail: str) -> None:
        if reason not in REJECTION_REASONS:
            raise ValueError(f"unknown rejection reason {reason!r}")
        super().__init__(f"{reason}: {detail}")
        self.reason = reason
        self.detail = detail


class MalformedMessageError(AdapterError):
    """Bytes that are not a serialized message of the expected type."""
