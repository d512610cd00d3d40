"""The standard-library udpm transport against LCM's own C implementation: what it
publishes (short and fragmented) is logged by Debian's lcm-logger byte for byte, and what
the C++ client publishes (multi-MB scans) it receives as lcm-logger does. Runs inside a
network namespace of its own (tests/python/run-in-netns)."""

import os
import random
import signal
import subprocess
import tempfile
import time
import unittest

import octomap_rt
from octomap_rt.udpm import FRAGMENT_MAX_PAYLOAD, SHORT_MESSAGE_MAX_SIZE, UdpmTransport, encode_datagrams

import lcm_log


def rmem_max():
    with open("/proc/sys/net/core/rmem_max") as f:
        return int(f.read())


def test_url(port):
    return f"udpm://239.255.76.67:{port}?ttl=0&recv_buf_size={min(4194304, rmem_max())}"


PROBE_CHANNEL = "LOGGER_READY_PROBE"


class Logger:
    """Debian's lcm-logger on a URL, stopped with SIGINT (it then flushes the log). Ready once
    it has logged a probe message: a message sent before its socket joined the group would be
    missing from the log, and the machine's load decides how long joining takes."""

    def __init__(self, url, path, timeout_s=30.0):
        self.path = path
        # 1.3.1's short option -l is broken (missing from its optstring): use --lcm-url=.
        self.proc = subprocess.Popen(["lcm-logger", "--quiet", "--flush-interval=50", f"--lcm-url={url}", path],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        deadline = time.monotonic() + timeout_s
        with UdpmTransport(url) as probe:
            while not (os.path.exists(path) and os.path.getsize(path) > 0):
                if self.proc.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"lcm-logger logged nothing within {timeout_s} s: {self.stop()}")
                probe.publish(PROBE_CHANNEL, b"")
                time.sleep(0.1)

    def events(self):
        """What it logged, the probes left out."""
        return [e for e in lcm_log.read_events(self.path) if e[0] != PROBE_CHANNEL]

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
        _, err = self.proc.communicate(timeout=20)
        return err.decode(errors="replace")


class FramingTest(unittest.TestCase):
    def test_short_and_fragmented_sizes(self):
        self.assertEqual(len(encode_datagrams("A", b"x" * 10, 7)), 1)
        limit = SHORT_MESSAGE_MAX_SIZE - len("CH") - 1
        self.assertEqual(len(encode_datagrams("CH", b"x" * limit, 1)), 1)
        frags = encode_datagrams("CH", b"x" * (limit + 1), 1)
        self.assertEqual(len(frags), 2)
        self.assertTrue(all(len(f) - 20 <= FRAGMENT_MAX_PAYLOAD for f in frags))
        self.assertEqual(len(encode_datagrams("CH", b"x" * 3_000_000, 1)), 46)


class AgainstLcmTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="ort-py-udpm-")
        self.url = test_url(20000 + os.getpid() % 20000)

    def test_lcm_logger_records_what_python_publishes(self):
        rng = random.Random(5)
        sizes = [0, 100, 65000, SHORT_MESSAGE_MAX_SIZE - 8, 300_000, 1_500_000]
        sent = [(f"PY_{i}", bytes(rng.getrandbits(8) for _ in range(n))) for i, n in enumerate(sizes)]
        logger = Logger(self.url, os.path.join(self.dir, "py.lcmlog"))
        with UdpmTransport(self.url) as t:
            for channel, payload in sent:
                t.publish(channel, payload)
                time.sleep(0.05)  # paced, as scans are: one message's fragments at a time
        time.sleep(0.5)
        err = logger.stop()
        logged = logger.events()
        self.assertEqual([c for c, _ in logged], [c for c, _ in sent], err)
        for (channel, payload), (_, got) in zip(sent, logged):
            self.assertEqual(got, payload, f"{channel}: {len(got)} bytes logged, {len(payload)} sent")

    def test_python_receives_what_the_cpp_client_publishes(self):
        cli = os.environ["OCTOMAP_RT_CLI"]
        received = []
        logger = Logger(self.url, os.path.join(self.dir, "cpp.lcmlog"))
        with UdpmTransport(self.url) as t:
            t.subscribe("OCTOMAP_RT_SCAN_.*", lambda channel, data: received.append((channel, data)))
            replay = subprocess.Popen([cli, "replay", "synthetic", "--robot", "pyrobot", "--first", "0",
                                       "--count", "3", "--rate", "4", "--lcm-url", self.url, "-q"],
                                      stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
            deadline = time.monotonic() + 60
            while replay.poll() is None and time.monotonic() < deadline:
                t.handle(0.1)
            t.handle(0.5)
            _, replay_err = replay.communicate(timeout=10)
            self.assertEqual(replay.returncode, 0, replay_err.decode(errors="replace"))
        err = logger.stop()
        logged = logger.events()
        self.assertEqual(len(logged), 3, err)
        self.assertEqual(received, logged)  # same channels, same bytes, same order
        scan = octomap_rt.scan_t.decode(received[0][1])
        self.assertEqual(received[0][0], "OCTOMAP_RT_SCAN_PYROBOT")
        self.assertEqual(scan.robot_id, "pyrobot")
        self.assertEqual(scan.seq, 0)
        self.assertEqual(scan.num_xyz, len(scan.xyz))
        self.assertGreater(len(received[0][1]), FRAGMENT_MAX_PAYLOAD * 2)  # a fragmented message


if __name__ == "__main__":
    unittest.main()
