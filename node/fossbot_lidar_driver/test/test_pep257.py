"""ament_pep257 over the package, as `ros2 pkg create` generates it."""

from ament_pep257.main import main
import pytest


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257():
    """The docstrings follow PEP 257 as ament checks it."""
    rc = main(argv=['.', 'test'])
    assert rc == 0, 'Found code style errors / warnings'
