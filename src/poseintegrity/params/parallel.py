"""The ``parallel`` section of ``params.yaml``: where the per-frame and per-dataset tasks run
(:class:`poseintegrity.workers.Workers` runs them)."""

from __future__ import annotations

from typing import Literal
from urllib.parse import urlsplit

from pydantic import Field, ValidationInfo, field_validator

from poseintegrity.schema import Section, WorkerCount

DASK_SCHEMES = ("tcp", "tls", "ws", "wss")


class ParallelParams(Section):
    """The ``parallel`` section of ``params.yaml``: where the per-frame and per-dataset tasks run."""

    backend: Literal["local", "dask"] = Field(
        "local", description="local: joblib (loky) worker processes on this machine; dask: a Dask cluster")
    address: str | None = Field(
        None, description="dask only: a scheduler address such as tcp://host:8786; null starts a LocalCluster "
                          "of n_jobs single-threaded worker processes on this machine")
    n_jobs: WorkerCount = Field(
        2, description="worker processes of the local backend and of a LocalCluster (-1: all cores); "
                       "a scheduler at `address` has the workers that joined it")

    @field_validator("address")
    @classmethod
    def _valid_address(cls, address: str | None, info: ValidationInfo) -> str | None:
        if address is None:
            return None
        if info.data.get("backend") != "dask":
            raise ValueError("an address is only used with backend: dask (set backend: dask, or address: null)")
        parts = urlsplit(address)
        if parts.scheme not in DASK_SCHEMES or not parts.hostname or parts.path or _port(parts) is None:
            raise ValueError(f"expected a Dask scheduler address such as tcp://host:8786 "
                             f"(schemes {', '.join(DASK_SCHEMES)}), got {address!r}")
        return address


def _port(parts) -> int | None:
    try:
        return parts.port
    except ValueError:  # not a number or out of range
        return None
