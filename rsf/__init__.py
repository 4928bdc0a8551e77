"""Rate-and-state friction for a spring-slider (temporary init during development)."""
from __future__ import annotations
