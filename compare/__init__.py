"""compare — the microscopic model (micro) and rate-and-state friction (rsf) side by side."""
from __future__ import annotations

from .cache import NullCache, PointCache
from .runner import Runner
from .tasks import CriticalTask, SlideHoldSlideTask, StationaryTask, execute

__all__ = ["PointCache", "NullCache", "Runner", "StationaryTask", "CriticalTask", "SlideHoldSlideTask",
           "execute"]
