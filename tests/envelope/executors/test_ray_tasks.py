"""envelope.executors.ray_tasks without a cluster: checked configs, fast failure on a dead address,
and
tasks that no node could run refused up front."""

import pytest

from envelope.executors.ray_tasks import RayConfig, TaskResources, _check_fits, ray_session


def test_configs_are_checked():
    with pytest.raises(ValueError, match="num_cpus"):
        RayConfig(num_cpus=0)
    with pytest.raises(ValueError, match="max_retries"):
        RayConfig(max_retries=-1)
    with pytest.raises(ValueError, match=">= 0"):
        TaskResources(gpus=-1.0)


def test_an_address_nobody_answers_at_fails_at_once_with_a_fix():
    pytest.importorskip("ray", reason="the ray executor needs Ray (scripts/setup.sh)")
    import ray

    if ray.is_initialized():
        pytest.skip("a Ray of another test is still running in this process")
    with pytest.raises(ValueError, match="cannot reach a Ray cluster.*ray start --head"):
        with ray_session(RayConfig(address="127.0.0.1:1")):
            pass


def test_a_task_larger_than_the_cluster_is_refused():
    calls = [((), TaskResources(cpus=1.0)), ((), TaskResources(cpus=1.0, gpus=1.0))]
    _check_fits(calls[:1], {"CPU": 2.0})
    with pytest.raises(ValueError, match="needs 1 GPU"):
        _check_fits(calls, {"CPU": 2.0})
    with pytest.raises(ValueError, match="needs 4 CPU"):
        _check_fits([((), TaskResources(cpus=4.0))], {"CPU": 2.0, "GPU": 1.0})
