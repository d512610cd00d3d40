"""The rough edges a new user hit with the command-line programs (issue 24, "Rough edges"),
against a real octomap-rt-server in this test's network namespace: every program says its
version and protocol version, help texts name choices as a user types them (no enum
internals), `query grid --json` gives the cells, and `map watch | head` ends cleanly when its
reader goes away and still writes --save."""

import json
import os
import subprocess

from octomap_rt.protocol_table import PROTOCOL_VERSION
from server_fixture import CLI, SERVER, ServerTestCase

PLAN = os.path.join(os.path.dirname(CLI), "octomap-rt-plan")


class CliEdges(ServerTestCase):
    def test_every_program_says_its_version_and_protocol_version(self):
        for program in (CLI, SERVER, PLAN):
            out = subprocess.run([program, "--version"], capture_output=True, text=True, timeout=30)
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn(f"(protocol version {PROTOCOL_VERSION}", out.stdout)

    def test_help_texts_name_choices_as_a_user_types_them(self):
        for command in ([SERVER, "--help"], [CLI, "query", "grid", "--help"], [CLI, "replay", "--help"],
                        [PLAN, "--help"]):
            text = subprocess.run(command, capture_output=True, text=True, timeout=30).stdout
            self.assertNotIn("->", text, command)  # CLI11's enum maps ("cpu->0")
            self.assertNotIn("ENUM", text, command)
            self.assertNotRegex(text, r"\bk[A-Z][a-z]+", command)  # C++ enumerator names (kCpu)

    def test_query_grid_json_gives_the_cells(self):
        self.publish_wall(2.0, "gridbot")
        out = subprocess.run([CLI, "query", "grid", "--json", "--z", "0.45:1.55", "--lcm-url", self.url,
                              "--timeout", "30"], capture_output=True, text=True, timeout=60)
        self.assertEqual(out.returncode, 0, out.stderr)
        grid = json.loads(out.stdout)
        cells = grid["cells"]
        self.assertEqual(len(cells), grid["height"])
        self.assertTrue(all(len(row) == grid["width"] for row in cells))
        occupied = sum(row.count(grid["cell_values"]["occupied"]) for row in cells)
        self.assertGreater(occupied, 0)  # the wall
        self.assertEqual(occupied, grid["counts"]["occupied"])

    def test_map_watch_into_a_closed_pipe_ends_and_still_saves(self):
        self.publish_wall(2.5, "watchbot")
        saved = os.path.join(self.dir, "watched.ot")
        watch = subprocess.Popen([CLI, "map", "watch", "--save", saved, "--seconds", "60", "--lcm-url", self.url],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        first = watch.stdout.readline()  # `| head -1`: one line, then the reader goes away
        self.assertIn(b"mirror of snapshot", first)
        watch.stdout.close()
        code = watch.wait(timeout=60)
        stderr = watch.stderr.read().decode()
        watch.stderr.close()
        self.assertEqual(code, 0, stderr)  # not -13 (SIGPIPE)
        self.assertTrue(os.path.getsize(saved) > 0, stderr)
