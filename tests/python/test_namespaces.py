"""Two servers in two namespaces on one LCM URL (issue 24, item 3): each client talks only to
its own server (the CLI, Python and the Java examples), every channel (status, map info,
queries, edits, scans, the viewer's OCTOMAP) carries its namespace, nothing goes out under
today's names, and a namespace that would make a channel longer than LCM's 63 characters stops
the server at start."""

import json
import os
import subprocess
import time
import unittest

import numpy as np

import octomap_rt
from server_fixture import CLI, SERVER, ServerGroup

JAVA_CP = os.environ.get("OCTOMAP_RT_JAVA_CP", "")  # lcm.jar, our types jar, the examples' jar


def start_server(group, ns, server_id, use_env=False):
    env = dict(os.environ)
    args = [SERVER, "-r", "0.1", "--lcm-url", group.url, "--backend", "cpu", "--server-id", server_id,
            "--octomap-raw-rate", "4", "--warm-up-points", "0"]
    if use_env:
        env["OCTOMAP_RT_NAMESPACE"] = ns
    else:
        args += ["--namespace", ns]
    return group.start(args, env=env)


def messages_on(transport, channel_regex, seconds):
    seen = []
    sub = transport.subscribe(channel_regex, lambda channel, _data: seen.append(channel))
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        transport.handle(0.1)
    transport.unsubscribe(sub)
    return seen


class TwoNamespacesOnOneUrl(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.group = ServerGroup("ort-py-ns-", 11, 5)
        cls.url = cls.group.url
        start_server(cls.group, "lab_a", "server-a")
        start_server(cls.group, "lab_b", "server-b", use_env=True)
        cls.a = octomap_rt.MapClient(cls.url, namespace="lab_a")
        cls.b = octomap_rt.MapClient(cls.url, namespace="lab_b")
        for client in (cls.a, cls.b):
            client.status(timeout_s=60)

    @classmethod
    def tearDownClass(cls):
        for client in (cls.a, cls.b):
            client.close()
        cls.group.stop()

    def test_each_client_hears_only_its_own_server(self):
        for _ in range(3):
            self.assertEqual(self.a.status(timeout_s=5).server_id, "server-a")
            self.assertEqual(self.b.status(timeout_s=5).server_id, "server-b")
        self.assertEqual(self.a.channels.status, "lab_a_OCTOMAP_RT_STATUS")

    def test_a_scan_and_a_query_stay_in_their_namespace(self):
        wall = np.array([[2.0, y, z] for y in np.linspace(-1, 1, 21) for z in np.linspace(0, 1, 11)])
        self.a.publish_scan(wall, robot_id="rover", origin=(0.0, 0.0, 0.5))
        status = self.a.wait_for(self.a.channels.status, octomap_rt.server_status_t.decode, timeout_s=60,
                                 accept=lambda s: any(r.scans_applied == 1 for r in s.robots))
        self.assertEqual(status.server_id, "server-a")
        self.assertEqual(self.b.status().num_robots, 0)
        end = wall + np.array([0.0, 0.0, 0.5])
        occ_a, _ = self.a.query_points(end[:5])
        occ_b, _ = self.b.query_points(end[:5])
        self.assertTrue((occ_a == octomap_rt.OCCUPIED).all(), occ_a)
        self.assertTrue((occ_b == octomap_rt.UNKNOWN).all(), occ_b)

    def test_nothing_goes_out_under_todays_names(self):
        seen = messages_on(self.a.transport, ".*", 2.5)
        self.assertIn("lab_a_OCTOMAP", seen)  # the viewer's channel carries the namespace too
        self.assertIn("lab_b_OCTOMAP", seen)
        self.assertIn("lab_b_OCTOMAP_RT_MAP_INFO", seen)
        bare = [c for c in seen if not c.startswith(("lab_a_", "lab_b_"))]
        self.assertEqual(bare, [])

    def test_the_cli_takes_the_namespace_by_flag_and_by_environment(self):
        out = subprocess.run([CLI, "status", "--json", "--lcm-url", self.url, "--namespace", "lab_b"],
                             capture_output=True, text=True, timeout=60, check=True).stdout
        self.assertEqual(json.loads(out)["server_id"], "server-b")
        env = dict(os.environ, OCTOMAP_RT_NAMESPACE="lab_a")
        out = subprocess.run([CLI, "status", "--json", "--lcm-url", self.url], capture_output=True, text=True,
                             timeout=60, check=True, env=env).stdout
        self.assertEqual(json.loads(out)["server_id"], "server-a")
        info = subprocess.run([CLI, "map", "info", "--json", "--lcm-url", self.url, "--namespace", "lab_b"],
                              capture_output=True, text=True, timeout=60)
        self.assertEqual(info.returncode, 0, info.stderr)

    @unittest.skipUnless(JAVA_CP, "no JDK: the Java examples were not built")
    def test_the_java_examples_take_the_namespace_from_the_environment(self):
        java = ["java", "-Djava.net.preferIPv4Stack=true", "-cp", JAVA_CP]
        env = dict(os.environ, OCTOMAP_RT_NAMESPACE="lab_b")
        run = subprocess.run(java + ["StatusListener", self.url, "2"], capture_output=True, text=True, timeout=60,
                             env=env)
        self.assertEqual(run.returncode, 0, run.stderr)
        heard = [line for line in run.stdout.splitlines() if ": state " in line]
        self.assertEqual(len(heard), 2, run.stdout)
        self.assertTrue(all(line.startswith("server-b: ") for line in heard), run.stdout)
        # An edit goes to the namespace's edit channel, signed for it, and its acknowledgement
        # comes back on the namespace's reply channel: server-a has no control token, so it
        # refuses the edit and says why (without the namespace nobody answers: exit 2).
        env["OCTOMAP_RT_NAMESPACE"] = "lab_a"
        edit = subprocess.run(java + ["MapEdit", self.url, "any-token", "reset"], capture_output=True, text=True,
                              timeout=60, env=env)
        self.assertEqual(edit.returncode, 3, edit.stdout + edit.stderr)
        self.assertIn("map edits are off", edit.stdout)

    def test_a_namespace_too_long_for_lcm_stops_the_server_at_start(self):
        run = subprocess.run([SERVER, "-r", "0.1", "--lcm-url", self.url, "--backend", "cpu",
                              "--namespace", "n" * 41], capture_output=True, text=True, timeout=60)
        self.assertNotEqual(run.returncode, 0)
        self.assertIn("at most 63", run.stderr + run.stdout)
        run = subprocess.run([SERVER, "-r", "0.1", "--namespace", "lab-a"], capture_output=True, text=True,
                             timeout=60)
        self.assertNotEqual(run.returncode, 0)
        self.assertIn("letters, digits", run.stderr + run.stdout)


if __name__ == "__main__":
    unittest.main()
