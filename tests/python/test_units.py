"""The client's pure parts, without a server: SSE parsing, problem rendering,
the progress line, spec loading and download-name safety."""

from __future__ import annotations

import io
import unittest

from hmpm_client import HmpmError
from hmpm_client.client import _safe_relative, _spec_bytes, _spec_end_time
from hmpm_client.events import read_events
from hmpm_client.progress import ProgressBar, format_duration


class EventsTest(unittest.TestCase):
    def test_parses_events_heartbeats_and_multiline_data(self):
        raw = (b"retry: 2000\n\n"
               b"id: 1\nevent: progress\ndata: {\"progress\": 5}\n\n"
               b": heartbeat\n\n"
               b"data: line one\r\ndata: line two\r\n\r\n"
               b"event: done\ndata:{\"status\": \"successful\"}\n")
        events = list(read_events(raw.splitlines(keepends=True)))
        self.assertEqual([(e.name, e.data) for e in events], [
            ("progress", '{"progress": 5}'),
            ("heartbeat", ""),
            ("message", "line one\nline two"),
            ("done", '{"status": "successful"}'),
        ])
        self.assertEqual(events[0].id, "1")


class HmpmErrorTest(unittest.TestCase):
    def test_lists_every_path_and_message(self):
        e = HmpmError({"type": "invalid-spec", "title": "Invalid job spec", "status": 400,
                       "detail": "the job spec has 2 problems",
                       "errors": [{"path": "/materials/bar/youngs_modulus", "message": "must be > 0"},
                                  {"path": "/time/end", "message": "is required"}]})
        self.assertEqual(e.status, 400)
        self.assertTrue(e.type_is("invalid-spec"))
        self.assertEqual(str(e).splitlines(), [
            "Invalid job spec (HTTP 400): the job spec has 2 problems",
            "  /materials/bar/youngs_modulus: must be > 0",
            "  /time/end: is required",
        ])

    def test_type_uri_suffix(self):
        e = HmpmError({"type": "https://hmpm.example/problems/result-not-ready", "title": "x"}, 404)
        self.assertTrue(e.type_is("result-not-ready"))
        self.assertFalse(e.type_is("not-ready"))


class ProgressTest(unittest.TestCase):
    def test_line_has_percent_simulated_time_and_eta(self):
        out = io.StringIO()
        bar = ProgressBar("job-1", out)
        doc = {"status": "running", "progress": 0, "cost": {"steps": 2000, "dt": 0.001}}
        bar.update(doc)
        bar._start = (bar._start[0] - 10.0, 0.0)  # pretend 10 s have passed
        line = bar.render(dict(doc, progress=50))
        self.assertIn(" 50%", line)
        self.assertIn("t=1/2 s", line)
        self.assertRegex(line, r"ETA (9|10|11)s")
        bar.finish({"status": "successful", "progress": 100})
        self.assertIn("100%", out.getvalue().splitlines()[-1])
        self.assertIn("successful", out.getvalue().splitlines()[-1])

    def test_non_tty_output_is_short(self):
        out = io.StringIO()
        bar = ProgressBar("j", out)
        for p in range(0, 101):
            bar.update({"status": "running", "progress": p})
        bar.finish({"status": "successful", "progress": 100})
        self.assertLessEqual(len(out.getvalue().splitlines()), 13)

    def test_durations(self):
        self.assertEqual(format_duration(None), "--")
        self.assertEqual(format_duration(7.2), "7s")
        self.assertEqual(format_duration(65), "1m05s")
        self.assertEqual(format_duration(7380), "2h03m")


class SpecAndNamesTest(unittest.TestCase):
    def test_spec_forms(self):
        self.assertEqual(_spec_bytes({"a": 1}), b'{"a": 1}')
        self.assertEqual(_spec_bytes('  {"a": 1}'), b'  {"a": 1}')
        self.assertEqual(_spec_bytes(b"raw"), b"raw")
        self.assertEqual(_spec_end_time(b'{"time": {"end": 2.5}}'), 2.5)
        self.assertIsNone(_spec_end_time(b"not json"))

    def test_unsafe_names_are_refused(self):
        self.assertEqual(str(_safe_relative("snapshots/s_0001.vtu")), "snapshots/s_0001.vtu")
        for bad in ("", "/etc/passwd", "../x", "a/../../x", "c:x", "a\\..\\..\\x"):
            with self.assertRaises(HmpmError, msg=bad):
                _safe_relative(bad)


if __name__ == "__main__":
    unittest.main()
