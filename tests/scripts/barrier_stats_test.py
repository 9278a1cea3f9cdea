"""scripts/barrier-stats.py on traces whose barrier times are known."""
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "barrier-stats.py")
spec = importlib.util.spec_from_file_location("barrier_stats", SCRIPT)
barrier_stats = importlib.util.module_from_spec(spec)
spec.loader.exec_module(barrier_stats)


def arrival(sender, receivers, node, sent, received):
    return [{"t": received, "event": "message", "drone": r, "kind": "trigger", "from": sender, "to": r,
             "node": node, "sent": sent, "received": received} for r in receivers]


def fork(drone, node, t):
    return {"t": t, "drone": drone, "event": "node", "kind": "fork", "outcome": "ended", "node": node}


def two_drone_barrier(node, a_sent, b_sent, a_goes_on, b_goes_on):
    return (arrival("A", ["B"], node, a_sent, a_sent + 0.001) + arrival("B", ["A"], node, b_sent, b_sent + 0.001) +
            [fork("A", node, a_goes_on), fork("B", node, b_goes_on)])


class BarrierStats(unittest.TestCase):
    def test_a_barrier_lasts_from_the_last_arrival_to_the_last_continuation(self):
        # B arrives last at 2.0; A goes on at 2.010, B at 2.030: 30 ms, whatever A waited.
        events = two_drone_barrier(7, 1.0, 2.0, 2.010, 2.030)
        [(node, k, last, went_on, drones)] = barrier_stats.barriers(events)
        self.assertEqual((node, k, drones), (7, 0, 2))
        self.assertAlmostEqual(went_on - last, 0.030)

    def test_each_pass_of_a_sync_point_in_a_loop_is_a_barrier_of_its_own(self):
        events = two_drone_barrier(3, 1.0, 1.5, 1.51, 1.52) + two_drone_barrier(3, 5.0, 5.5, 5.6, 5.7)
        s = barrier_stats.summary(barrier_stats.barriers(events), 2.0)
        self.assertEqual(s["barriers"], 2)
        self.assertAlmostEqual(s["max_s"], 0.2)
        self.assertAlmostEqual(s["max_wall_ms"], 100.0)  # at --speed 2

    def test_median_and_p99_are_nearest_ranks(self):
        values = list(range(1, 101))
        self.assertEqual(barrier_stats.percentile(values, 50), 50)
        self.assertEqual(barrier_stats.percentile(values, 99), 99)
        self.assertEqual(barrier_stats.percentile([4.0], 99), 4.0)

    def test_a_fork_no_drone_arrived_at_by_message_is_no_barrier(self):
        self.assertEqual(barrier_stats.barriers([fork("A", 1, 0.0), fork("B", 1, 0.0)]), [])

    def test_a_line_that_is_not_json_is_reported_at_its_line(self):
        with tempfile.NamedTemporaryFile("w", suffix=".jsonl", delete=False) as f:
            f.write(json.dumps(fork("A", 1, 0.0)) + "\n{not json\n")
        try:
            run = subprocess.run([sys.executable, SCRIPT, f.name], capture_output=True, text=True)
        finally:
            os.unlink(f.name)
        self.assertEqual(run.returncode, 1)
        self.assertIn(f"{f.name}:2:2: error: not a JSON line", run.stderr)
        self.assertNotIn("Traceback", run.stderr)


if __name__ == "__main__":
    unittest.main()
