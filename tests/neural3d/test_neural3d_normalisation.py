"""World metres <-> normalised frame."""

import numpy as np
import pytest
import torch

from neural3d.field.normalisation import Normalisation


def test_round_trip_and_unit_box():
    n = Normalisation.from_box(np.array([-10.0, -6.0, 0.0]), np.array([10.0, 6.0, 9.0]))
    assert n.scale_m == 10.0 and np.allclose(n.centre_m, [0, 0, 4.5])
    assert np.allclose(n.box_min_unit, [-1, -0.6, -0.45]) and np.allclose(n.box_max_unit,
                                                                          [1, 0.6, 0.45])
    p = torch.tensor([[3.0, -2.0, 7.5]], dtype=torch.float64)
    assert torch.allclose(n.world_from_unit(n.unit_from_world(p)), p)
    assert Normalisation.from_json_dict(n.to_json_dict()) == n


def test_bad_box():
    with pytest.raises(ValueError, match="max > min"):
        Normalisation((0.0, 0.0, 0.0), (1.0, 0.0, 1.0))
