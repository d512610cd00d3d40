"""What the Python client tests share: a real octomap-rt-server (cpu back end, 0.1 m,
publishing OCTOMAP) on a test URL of their network namespace, a MapClient on it, and
helpers to publish a wall of points and to name voxels as OctoMap does."""

import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

import numpy as np

import octomap_rt
from octomap_rt.shards import ShardClient

SERVER = os.environ.get("OCTOMAP_RT_SERVER", "")
CLI = os.environ.get("OCTOMAP_RT_CLI", "")
EXAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "client", "bindings", "python", "examples",
                       "planner.py")


def test_url(port):
    with open("/proc/sys/net/core/rmem_max") as f:
        rmem_max = int(f.read())
    return f"udpm://239.255.76.67:{port}?ttl=0&recv_buf_size={min(4194304, rmem_max)}"


def voxel_keys(points, resolution=0.1):
    """OctoMap's coordToKey of float32 points (what a scan carries), as a set of triples
    (minus the constant 32768)."""
    coords = np.asarray(points, dtype=np.float32).astype(np.float64)
    return {tuple(k) for k in np.floor(coords * (1.0 / resolution)).astype(int)}


class ServerGroup:
    """The servers one test class starts itself (each with its own flags) on one test URL,
    with one folder and one log: stop() ends those still running (SIGTERM) and removes the
    folder when every one exited 0 (OCTOMAP_RT_KEEP_TEST_DIRS keeps it)."""

    def __init__(self, prefix, port_factor, port_offset):
        self.dir = tempfile.mkdtemp(prefix=prefix)
        self.url = test_url(20000 + (os.getpid() * port_factor + port_offset) % 20000)
        self.log = open(os.path.join(self.dir, "servers.log"), "w")
        self.servers = []

    def start(self, args, env=None):
        server = subprocess.Popen(args, stdout=self.log, stderr=subprocess.STDOUT, env=env)
        self.servers.append(server)
        return server

    def stop(self):
        codes = []
        for server in self.servers:
            if server.poll() is None:
                server.send_signal(signal.SIGTERM)
            codes.append(server.wait(timeout=60))
        self.log.close()
        if all(c == 0 for c in codes) and not os.environ.get("OCTOMAP_RT_KEEP_TEST_DIRS"):
            shutil.rmtree(self.dir, ignore_errors=True)
        return codes


class ShardSetGroup(ServerGroup):
    """What the shard tests compare (issue 26): `count` servers --shard i/count in namespace
    "campus" and one whole daemon in namespace "one", all with the flags `common` (after the URL,
    the cpu back end and no warm-up), on one test URL. `whole` is a MapClient of the whole daemon
    (its first status awaited), `shards` a ShardClient of the set; stop() closes both."""

    def __init__(self, prefix, port_factor, port_offset, count, depth, common):
        super().__init__(prefix, port_factor, port_offset)
        base = [SERVER, "--lcm-url", self.url, "--backend", "cpu", "--warm-up-points", "0"] + list(common)
        for i in range(count):
            self.start(base + ["--namespace", "campus", "--shard", f"{i}/{count}", "--shard-region-depth", str(depth),
                               "--server-id", f"shard-{i}"])
        self.start(base + ["--namespace", "one", "--server-id", "whole"])
        self.whole = octomap_rt.MapClient(self.url, namespace="one")
        self.whole.status(timeout_s=60)
        self.shards = ShardClient(transport=octomap_rt.open_transport(self.url), namespace="campus", timeout_s=60)

    def wait_statuses(self, client, pred, statuses, timeout_s=120):
        """Waits for statuses satisfying `pred` on `client`'s namespace from `statuses` servers
        (told apart by their shard index); returns the indices heard."""
        done, deadline = set(), time.monotonic() + timeout_s
        while len(done) < statuses and time.monotonic() < deadline:
            s = client.wait_for(client.channels.status, octomap_rt.server_status_t.decode, pred, timeout_s=60)
            done.add(s.shard_index)
        return done

    def stop(self):
        self.whole.close(), self.shards.close()
        return super().stop()


class ServerTestCase(unittest.TestCase):
    server_args = []  # more flags for the server (a test class's own)

    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="ort-py-client-")
        cls.url = test_url(20000 + (os.getpid() * 7 + 3) % 20000)
        cls.log = open(os.path.join(cls.dir, "server.log"), "w")
        cls.server = subprocess.Popen([SERVER, "-r", "0.1", "--lcm-url", cls.url, "--backend", "cpu",
                                       "--octomap-raw-rate", "5", "--octomap-raw-max-kib", "4096"] + cls.server_args,
                                      stdout=cls.log, stderr=subprocess.STDOUT)
        cls.client = octomap_rt.MapClient(cls.url)
        cls.wait_until_listening()

    @classmethod
    def wait_until_listening(cls, timeout_s: float = 60.0):
        """Returns once the server has sent a status. It sends its first one after it has
        subscribed to the scan and service channels, so from then on nothing a test publishes
        is lost; a scan published earlier can reach no socket and is gone without a trace."""
        deadline = time.monotonic() + timeout_s
        while True:
            if cls.server.poll() is not None:
                with open(os.path.join(cls.dir, "server.log")) as f:
                    raise RuntimeError(f"octomap-rt-server exited with {cls.server.returncode}:\n{f.read()}")
            try:
                cls.client.status(timeout_s=1.0)
                return
            except octomap_rt.ServerTimeout:
                if time.monotonic() > deadline:
                    raise

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.server.send_signal(signal.SIGTERM)
        code = cls.server.wait(timeout=60)
        cls.log.close()
        # The folder holds the server's log and map: kept only where a run needs looking into.
        if code == 0 and not os.environ.get("OCTOMAP_RT_KEEP_TEST_DIRS"):
            shutil.rmtree(cls.dir, ignore_errors=True)

    def publish_wall(self, x: float, robot_id: str, origin=(0.0, 0.0, 0.5)):
        """A 2 m x 1 m wall of points at `x` from a sensor at `origin`, waited for until applied;
        returns the points in the map frame."""
        wall = np.array([[x, y, z] for y in np.linspace(-1, 1, 21) for z in np.linspace(0, 1, 11)])
        self.client.publish_scan(wall, robot_id=robot_id, origin=origin)
        self.client.wait_for("OCTOMAP_RT_STATUS", octomap_rt.server_status_t.decode, timeout_s=60,
                             accept=lambda s: any(r.robot_id.lower() == robot_id and r.scans_applied == 1
                                                  for r in s.robots))
        return wall + np.asarray(origin)
