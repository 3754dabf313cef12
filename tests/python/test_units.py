"""The client's pure parts, without a server: SSE parsing, problem rendering,
the progress line, spec loading and download-name safety."""

from __future__ import annotations

import io
import unittest
from unittest import mock

from hmpm_client import HmpmError
from hmpm_client.client import _safe_relative, _spec_bytes, _spec_end_time
from hmpm_client.events import read_events
from hmpm_client.progress import ProgressBar, format_duration
from hmpm_client.units import field_units, format_time, scaled_times, time_unit


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
        doc = {"status": "running", "progress": 0, "cost": {"steps": 2000, "dt": 0.001},
               "run": {"simulated_time": 0.0, "end_time": 2.0, "steps": 0}}
        bar.update(doc)
        bar._start = (bar._start[0] - 10.0, 0.0)  # pretend 10 s have passed
        line = bar.render(dict(doc, progress=50, run={"simulated_time": 1.0, "end_time": 2.0}))
        self.assertIn(" 50%", line)
        self.assertIn("t=1/2 s", line)
        self.assertRegex(line, r"ETA (9|10|11)s")
        bar.finish({"status": "successful", "progress": 100})
        self.assertIn("100%", out.getvalue().splitlines()[-1])
        self.assertIn("successful", out.getvalue().splitlines()[-1])

    def test_simulated_time_is_the_servers_never_the_estimate(self):
        # Issue 44: a 5-year quasi-static job showed 28 days (the estimated
        # steps times the first step). The server's `run` is what counts.
        five_years = 5 * 365.25 * 86400
        bar = ProgressBar("job-2", io.StringIO())
        doc = {"status": "running", "progress": 40, "cost": {"steps": 664, "dt": 3649.29},
               "run": {"simulated_time": 0.4 * five_years, "end_time": five_years}}
        self.assertIn("t=2/5 years", bar.render(doc))
        # Before the run reports, the spec's end (as submitted), not cost.
        bar = ProgressBar("job-3", io.StringIO(), end_time=five_years)
        line = bar.render({"status": "running", "progress": 10, "cost": {"steps": 664, "dt": 3649.29}})
        self.assertIn("t=0.5/5 years", line)
        # Neither: no simulated time at all rather than a wrong one.
        line = ProgressBar("job-4", io.StringIO()).render(
            {"status": "running", "progress": 10, "cost": {"steps": 664, "dt": 3649.29}})
        self.assertNotIn("t=", line)

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


class UnitsTest(unittest.TestCase):
    def test_time_unit_reads_best(self):
        self.assertEqual(time_unit(0.51), (1.0, "s"))
        self.assertEqual(time_unit(119), (1.0, "s"))
        self.assertEqual(time_unit(600)[1], "min")
        self.assertEqual(time_unit(5 * 3600)[1], "h")
        self.assertEqual(time_unit(10 * 86400), (86400.0, "days"))
        self.assertEqual(time_unit(1.578e8)[1], "years")
        self.assertEqual(format_time(1.5778800e8), "5 years")
        self.assertEqual(format_time(864000), "10 days")
        self.assertEqual(format_time(864000, span=1e8), "0.02738 years")
        times, unit = scaled_times([0, 43200, 172800])
        self.assertEqual((times, unit), ([0.0, 0.5, 2.0], "days"))

    def test_field_units_from_the_fields_document(self):
        doc = {"fields": [{"name": "pore_pressure", "kind": "scalar", "unit": "Pa"},
                          {"name": "strain", "kind": "tensor", "unit": "-"}, {"name": 3}]}
        self.assertEqual(field_units(doc), {"pore_pressure": "Pa", "strain": "-"})
        self.assertEqual(field_units(None), {})


def _have_matplotlib() -> bool:
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


@unittest.skipUnless(_have_matplotlib(), "matplotlib is not installed (Debian: python3-matplotlib)")
class PlotLabelsTest(unittest.TestCase):
    """What the plots say on their axes (issue 44): depth increasing
    downward, times in the unit that reads best, units from /fields."""

    UNITS = {"pore_pressure": "Pa", "displacement": "m"}
    TIMES = [0.0, 864000.0, 2629800.0, 31557600.0]  # 0, 10 days, 1 month, 1 year

    def capture(self, draw):
        from hmpm_client import plot
        figures = []
        with mock.patch.object(plot, "_save", lambda plt, fig, out: figures.append(fig) or out):
            draw(plot)
        self.assertEqual(len(figures), 1)
        return figures[0]

    def profiles(self, frm, to):
        points = [[frm[a] + (to[a] - frm[a]) * k / 4 for a in range(len(frm))] for k in range(5)]
        length = sum((to[a] - frm[a]) ** 2 for a in range(len(frm))) ** 0.5
        rows = [[1000.0 * (r + 1) * k for k in range(5)] for r in range(len(self.TIMES))]
        return {"time": self.TIMES, "profiles": [
            {"index": 0, "from": frm, "to": to, "points": points,
             "distance": [length * k / 4 for k in range(5)], "pore_pressure": rows}]}

    def test_vertical_profile_is_drawn_against_depth_downward(self):
        doc = self.profiles([5.0, 10.0], [5.0, 2.0])  # from the surface down
        fig = self.capture(lambda plot: plot.plot_profile(doc, "pore_pressure", "x.png", units=self.UNITS))
        ax = fig.axes[0]
        self.assertEqual(ax.get_ylabel(), "depth below y = 10 m [m]")
        self.assertTrue(ax.yaxis_inverted())
        self.assertEqual(ax.get_xlabel(), "pore_pressure [Pa]")
        depths = list(ax.lines[0].get_ydata())
        self.assertEqual(depths, [0.0, 2.0, 4.0, 6.0, 8.0])
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        self.assertEqual(labels, ["t = 0 s", "t = 10 days", "t = 30.44 days", "t = 1 years"])
        # The same line drawn upwards gives the same depths.
        doc = self.profiles([5.0, 2.0], [5.0, 10.0])
        fig = self.capture(lambda plot: plot.plot_profile(doc, "pore_pressure", "x.png", units=self.UNITS))
        self.assertEqual(sorted(fig.axes[0].lines[0].get_ydata()), [0.0, 2.0, 4.0, 6.0, 8.0])

    def test_horizontal_profile_is_drawn_along_its_distance(self):
        doc = self.profiles([0.0, 5.0], [8.0, 5.0])
        fig = self.capture(lambda plot: plot.plot_profile(doc, "pore_pressure", "x.png"))
        ax = fig.axes[0]
        self.assertEqual(ax.get_xlabel(), "distance from (0, 5) towards (8, 5) [m]")
        self.assertEqual(ax.get_ylabel(), "pore_pressure")  # no units given: none shown
        self.assertFalse(ax.yaxis_inverted())

    def test_series_time_axis_in_years(self):
        series = {"time": self.TIMES, "particles": [
            {"index": 0, "initial_position": [0.0, 1.0], "pore_pressure": [4.0, 3.0, 2.0, 1.0]}]}
        fig = self.capture(lambda plot: plot.plot_series(series, "pore_pressure", "x.png", units=self.UNITS))
        ax = fig.axes[0]
        self.assertEqual(ax.get_xlabel(), "time [years]")
        self.assertEqual(ax.get_ylabel(), "pore_pressure [Pa]")
        self.assertAlmostEqual(max(ax.lines[0].get_xdata()), 1.0)


class SpecAndNamesTest(unittest.TestCase):
    def test_spec_forms(self):
        self.assertEqual(_spec_bytes({"a": 1}), b'{"a": 1}')
        self.assertEqual(_spec_bytes('  {"a": 1}'), b'  {"a": 1}')
        self.assertEqual(_spec_bytes(b"raw"), b"raw")
        self.assertEqual(_spec_end_time(b'{"time": {"end": 2.5}}'), 2.5)
        # A staged job ends with its last stage.
        self.assertEqual(_spec_end_time(b'{"time": {"end": 1}, "stages": [{"end": 9}, {"end": 30}]}'), 30)
        self.assertIsNone(_spec_end_time(b"not json"))

    def test_unsafe_names_are_refused(self):
        self.assertEqual(str(_safe_relative("snapshots/s_0001.vtu")), "snapshots/s_0001.vtu")
        for bad in ("", "/etc/passwd", "../x", "a/../../x", "c:x", "a\\..\\..\\x"):
            with self.assertRaises(HmpmError, msg=bad):
                _safe_relative(bad)


if __name__ == "__main__":
    unittest.main()
