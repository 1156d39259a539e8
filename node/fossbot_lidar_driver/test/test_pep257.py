"""ament_pep257 over the package, as `ros2 pkg create` generates it."""

import pytest

ament_pep257_main = pytest.importorskip(
    'ament_pep257.main', reason='ament_pep257 is not installed'
).main
pytest.importorskip('pydocstyle', reason='pydocstyle is not installed (ament_pep257 runs it)')


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257():
    """The docstrings follow PEP 257 as ament checks it."""
    rc = ament_pep257_main(argv=['.', 'test'])
    assert rc == 0, 'Found code style errors / warnings'
