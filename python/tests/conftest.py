import os
import pathlib

import pytest

SOURCE = pathlib.Path(os.environ.get("CROWDDB_SOURCE_DIR", pathlib.Path(__file__).parents[2]))


@pytest.fixture
def source_dir() -> pathlib.Path:
    return SOURCE


@pytest.fixture
def cli() -> str:
    path = os.environ.get("CROWDDB_CLI")
    if not path:
        pytest.skip("CROWDDB_CLI is not set (ctest sets it)")
    return path
