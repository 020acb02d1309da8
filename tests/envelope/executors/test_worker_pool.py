"""Worker pool: results come back in order; an error in a worker reaches the parent."""

import math

import pytest

from envelope.executors.worker_pool import worker_pool


def test_pool_maps_in_order_and_propagates_errors():
    with worker_pool(2) as pool:
        assert pool.map(math.sqrt, [0.0, 4.0, 9.0]) == [0.0, 2.0, 3.0]
    with pytest.raises(ValueError, match="math domain error"), worker_pool(2) as pool:
        pool.map(math.sqrt, [4.0, -1.0])
    with pytest.raises(ValueError, match="workers must be >= 1"), worker_pool(0):
        pass
