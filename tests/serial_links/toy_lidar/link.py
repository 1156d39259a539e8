"""The toy LIDAR's link, as a link module in harness/links/ would be."""

from __future__ import annotations

from harness.links.base import register
from harness.links.board import BoardLink
from toy_lidar import NAME
from toy_lidar.preset import PROFILE


@register(NAME)
class ToyLink(BoardLink):
    """An emulated toy LIDAR read by its own board driver."""

    profile = PROFILE
