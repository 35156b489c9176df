"""Sweeps do not open ports to the network and never connect to a cluster named only by a file."""

import pytest

pytest.importorskip("distributed")

from eulerpoisson import InvalidInputError  # noqa: E402
from eulerpoisson.sweep import runner  # noqa: E402

CONFIG = """
[sweep]
kind = "grid"
[inertia]
I1 = 1.0
I2 = 2.0
I3 = 3.0
[momentum]
magnitude = 1.0
polar = {start = 10, stop = 170, num = 2}
azimuth = {start = 0, stop = 90, num = 2}
[compute]
T = 1.0
scheduler = "SCHED"
[output]
path = "atlas.zarr"
"""


def _config(tmp_path, scheduler):
    p = tmp_path / "sweep.toml"
    p.write_text(CONFIG.replace("SCHED", scheduler))
    return p


def test_a_scheduler_named_by_a_file_is_not_used_silently(tmp_path):
    cfg = _config(tmp_path, "tcp://198.51.100.7:8786")
    with pytest.raises(InvalidInputError, match="a file never connects to a cluster on its own"):
        runner.run_sweep(cfg, path=tmp_path / "a.zarr", progress=False)


@pytest.mark.parametrize("address", ["tcp://", "tcp://127.0.0.1", "tcp://:8786", "tls://host:port"])
def test_an_address_without_host_and_port_fails_at_once(tmp_path, address):
    with pytest.raises(InvalidInputError, match="must name a host and a port"):
        runner.run_sweep(_config(tmp_path, "local"), path=tmp_path / "a.zarr", scheduler=address, progress=False)


def test_the_local_cluster_listens_on_the_loopback_only():
    cluster = runner._local_cluster(1)
    try:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        link = cluster.dashboard_link
        assert "127.0.0.1" in link or "localhost" in link
    finally:
        cluster.close()
