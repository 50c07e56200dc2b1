"""A sweep split into chunks over a dask.distributed cluster of worker processes gives
exactly (bitwise) the single-process result: Motor pickles, solve is vectorised and each
point is solved independently of its neighbours."""
import numpy as np
import pytest

import trum

distributed = pytest.importorskip("distributed", reason="dask.distributed is not installed (pip install 'dask[distributed]')")


def test_local_cluster_is_bitwise_equal(motor):
    def solve_chunk(motor, preload_n, torque_nm):  # nested: cloudpickle ships it by value
        r = motor.solve(preload_n=preload_n, torque_nm=torque_nm, voltage_v=200.0, frequency_hz=43e3)
        return r.to_dict()

    m = motor.with_effects("hertz_softening=2e19")
    preload = np.linspace(100.0, 500.0, 600)
    torque = np.linspace(0.0, 0.6, 600)
    local = solve_chunk(m, preload, torque)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        futures = [client.submit(solve_chunk, m, p, t) for p, t in zip(np.array_split(preload, 7), np.array_split(torque, 7))]
        parts = client.gather(futures)
        pids = set(client.run(lambda: __import__("os").getpid()).values())
    assert len(pids) == 2
    for k in local:
        joined = np.concatenate([p[k] for p in parts])
        if joined.dtype.kind == "f":
            assert joined.tobytes() == local[k].tobytes(), k
        else:
            np.testing.assert_array_equal(joined, local[k])
