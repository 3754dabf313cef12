#!/usr/bin/env python3
"""The dashboard (GET /ui) in a real browser: headless Chromium from Debian,
driven by Debian's python3-selenium and chromedriver.

    apt-get install -y chromium chromium-driver python3-selenium
    /usr/bin/python3 tests/browser/test_dashboard.py            # build/bin/hmpm-server
    HMPM_BIN_DIR=/tmp/base-bin HMPM_UI_PROXY=1 /usr/bin/python3 tests/browser/test_dashboard.py
    HMPM_URL=http://127.0.0.1:8080 /usr/bin/python3 tests/browser/test_dashboard.py

HMPM_SCREENSHOTS=1 writes docs/figures/dashboard-*.png. Every wait is
bounded; everything stays on the loopback interface.
"""

import base64
import json
import os
import re
import struct
import sys
import unittest
import urllib.request
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from harness import REPO, Service, chromium, wait_until  # noqa: E402

from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.support.ui import Select  # noqa: E402

JOB_TIMEOUT_S = 180
UI_TIMEOUT_S = 20
SCREENSHOTS = os.environ.get("HMPM_SCREENSHOTS") == "1"
TOKEN = os.environ.get("HMPM_TOKEN", "")


def example(name):
    return json.loads((REPO / "examples" / f"{name}.json").read_text())


def short_terzaghi():
    """Terzaghi's column to T_v = 0.2 (20.4 s simulated, a few seconds of
    wall time): a series and four snapshots, long enough to see progress."""
    spec = example("terzaghi")
    spec["name"] = "terzaghi-short"
    spec["time"]["end"] = 20.4
    return spec


class Dashboard(unittest.TestCase):
    service = None
    driver = None

    @classmethod
    def setUpClass(cls):
        cls.service = Service()
        try:
            cls.driver = chromium()
            cls.jobs = {
                "bar": cls.submit(example("bar-vibration")),
                "terzaghi": cls.submit(short_terzaghi()),
                "collapse": cls.submit(example("column-collapse")),
                "soft-clay": cls.submit(example("soft-clay")),
            }
            for job_id in cls.jobs.values():
                cls.wait_job(job_id)
        except BaseException:
            cls.tearDownClass()
            raise

    @classmethod
    def tearDownClass(cls):
        if cls.driver:
            cls.driver.quit()
        if cls.service:
            cls.service.stop()

    def tearDown(self):
        # no script errors in the console (answers like 404 for a route the
        # server does not have yet are expected and reported by the page)
        errors = [e["message"] for e in self.driver.get_log("browser")
                  if e["level"] == "SEVERE" and "Failed to load resource" not in e["message"]]
        self.assertEqual(errors, [], "errors in the browser console")

    # --- HTTP helpers (the API directly, not through the page)
    @classmethod
    def call(cls, method, path, body=None):
        req = urllib.request.Request(cls.service.url + path, method=method, data=body)
        if body:  # the server takes JSON bodies only (415 otherwise)
            req.add_header("Content-Type", "application/json")
        if TOKEN:
            req.add_header("Authorization", f"Bearer {TOKEN}")
        with urllib.request.urlopen(req, timeout=30) as resp:
            return json.loads(resp.read() or b"null")

    @classmethod
    def submit(cls, spec):
        return cls.call("POST", "/jobs", json.dumps(spec).encode())["jobID"]

    @classmethod
    def wait_job(cls, job_id):
        return wait_until(lambda: cls.call("GET", f"/jobs/{job_id}")["status"] in ("successful", "failed", "dismissed"),
                          JOB_TIMEOUT_S, f"job {job_id} to finish")

    # --- page helpers
    def open(self, fragment):
        self.driver.get(f"{self.service.url}/ui{fragment}")
        if TOKEN:
            self.driver.execute_script("localStorage.setItem('hmpm.token', arguments[0])", TOKEN)
            self.driver.refresh()  # a get() of the same URL would only be a fragment change

    def css(self, selector, timeout=UI_TIMEOUT_S):
        return wait_until(lambda: self.driver.find_elements(By.CSS_SELECTOR, selector), timeout, selector)[0]

    def set_editor(self, text):
        self.driver.execute_script(
            "const t = document.getElementById('spec-text'); t.value = arguments[0];"
            "t.dispatchEvent(new Event('input', {bubbles: true}));", text)

    def screenshot(self, name):
        if not SCREENSHOTS:
            return
        height = self.driver.execute_script("return document.documentElement.scrollHeight")
        size = self.driver.get_window_size()
        self.driver.set_window_size(size["width"], min(max(height, 700), 2600))
        self.driver.execute_script("window.scrollTo(0, 0)")
        out = REPO / "docs" / "figures" / f"dashboard-{name}.png"
        self.driver.save_screenshot(str(out))
        self.driver.set_window_size(size["width"], size["height"])

    # --- tests
    def running_job(self):
        """A job that runs for a while (slope-failure: about 45 s); the
        caller dismisses it."""
        job_id = self.submit(example("slope-failure"))
        self.addCleanup(self.call, "DELETE", f"/jobs/{job_id}")
        return job_id

    def test_list_shows_every_job_with_id_name_status_and_progress(self):
        self.open("#/jobs")
        running = self.running_job()  # appears and runs without a reload
        wait_until(lambda: int(self.css(f'tr.job-row[data-job-id="{running}"] [role="progressbar"]').get_attribute("aria-valuenow")) > 0,
                   60, "the running job's progress in the list")
        self.assertEqual(self.css(f'tr.job-row[data-job-id="{running}"] .badge').text.lower(), "running")
        for key, job_id in self.jobs.items():
            row = self.css(f'tr.job-row[data-job-id="{job_id}"]')
            self.assertIn(job_id, row.text, "the full jobID is in the page")
            name = self.call("GET", f"/jobs/{job_id}")["name"]
            self.assertIn(name, row.find_element(By.CSS_SELECTOR, ".job-name").text)
            self.assertEqual(row.find_element(By.CSS_SELECTOR, ".badge").text.lower(), "successful")
            bar = row.find_element(By.CSS_SELECTOR, '[role="progressbar"]')
            self.assertEqual(bar.get_attribute("aria-valuenow"), "100")
        self.screenshot("list")
        # (a shared server given by HMPM_URL may hold other jobs too)
        def rows():
            return {r.get_attribute("data-job-id"): (r.find_element(By.CSS_SELECTOR, ".job-name").text, r.get_attribute("data-status"))
                    for r in self.driver.find_elements(By.CSS_SELECTOR, "tr.job-row")}

        # the name filter keeps only the matching jobs
        self.driver.find_element(By.ID, "filter-name").send_keys("terzaghi-short")
        wait_until(lambda: self.jobs["terzaghi"] in rows() and all(n == "terzaghi-short" for n, _ in rows().values()),
                   UI_TIMEOUT_S, "the name filter")
        # the status filter: none of our jobs has failed
        self.driver.find_element(By.ID, "filter-name").clear()
        Select(self.driver.find_element(By.ID, "filter-status")).select_by_value("failed")
        wait_until(lambda: not set(self.jobs.values()) & set(rows()) and all(s == "failed" for _, s in rows().values()),
                   UI_TIMEOUT_S, "the status filter")
        # a row opens its job page
        Select(self.driver.find_element(By.ID, "filter-status")).select_by_value("")
        self.css(f'tr.job-row[data-job-id="{self.jobs["bar"]}"] .job-name a').click()
        wait_until(lambda: self.driver.current_url.endswith(f"#/jobs/{self.jobs['bar']}"), UI_TIMEOUT_S, "the job page")

    def test_submit_with_errors_shows_each_beside_its_path(self):
        self.open("#/submit")
        spec = example("bar-vibration")
        spec["materials"]["bar"]["youngs_modulus"] = -1
        del spec["time"]
        self.set_editor(json.dumps(spec, indent=2))
        for path, words in (("/materials/bar/youngs_modulus", "> 0"), ("/time", "required")):
            item = self.css(f'#validation-errors li.problem[data-path="{path}"]')
            self.assertEqual(item.find_element(By.CSS_SELECTOR, ".path").text, path)
            self.assertIn(words, item.find_element(By.CSS_SELECTOR, ".problem-message").text)
        text = json.dumps(spec, indent=2)
        expected = next(i for i, l in enumerate(text.splitlines(), 1) if '"youngs_modulus"' in l)
        item = self.css('#validation-errors li.problem[data-path="/materials/bar/youngs_modulus"]')
        self.assertEqual(item.find_element(By.CSS_SELECTOR, ".line").text, f"line {expected}")
        item.find_element(By.CSS_SELECTOR, ".path").click()  # selects the member in the editor
        selected = self.driver.execute_script(
            "const t = document.getElementById('spec-text'); return t.value.slice(t.selectionStart, t.selectionEnd)")
        self.assertEqual(selected, '"youngs_modulus": -1')
        self.screenshot("submit-errors")
        # submitting anyway: the server refuses and the page stays, errors shown
        self.driver.find_element(By.ID, "submit-job").click()
        wait_until(lambda: "refused" in self.driver.find_element(By.ID, "validation-state").text, UI_TIMEOUT_S, "the refusal")
        self.assertTrue(self.driver.current_url.endswith("#/submit"))
        self.css('#validation-errors li.problem[data-path="/materials/bar/youngs_modulus"]')
        # a spec from a file replaces the text and is checked
        self.driver.find_element(By.ID, "spec-file").send_keys(str(REPO / "examples" / "geostatic.json"))
        wait_until(lambda: json.loads(self.css("#spec-text").get_attribute("value") or "{}").get("name") == "geostatic",
                   UI_TIMEOUT_S, "the file's text in the editor")
        wait_until(lambda: not self.driver.find_elements(By.CSS_SELECTOR, "#validation-errors li.problem"), UI_TIMEOUT_S, "no errors")
        # JSON syntax errors are caught before the server is asked
        self.set_editor('{"name": "x",')
        wait_until(lambda: "not valid JSON" in self.css('#validation-errors li.problem[data-path=""]').text, UI_TIMEOUT_S, "the syntax error")

    def test_validation_shows_warnings_beside_their_paths(self):
        spec = example("terzaghi")
        spec["materials"]["clay"]["density"] = 1000.0  # grains as light as water: a warning
        self.open("#/submit")
        self.set_editor(json.dumps(spec, indent=2))
        state = wait_until(lambda: (lambda c: c if c in ("valid", "idle") else None)(
            self.driver.find_element(By.ID, "validation-state").get_attribute("class").split()[-1]), UI_TIMEOUT_S, "validation")
        if state == "idle":
            self.skipTest("this server has no POST /validate")
        item = self.css('#validation-warnings li.problem[data-path="/materials/clay/hydraulic"]')
        self.assertIn("not denser than the fluid", item.text)
        self.assertIn("warning", self.driver.find_element(By.ID, "validation-state").text)

    def test_submit_valid_spec_and_watch_it_to_the_end(self):
        self.open("#/submit")
        Select(self.css("#example-select option[value='terzaghi']").find_element(By.XPATH, "..")).select_by_value("terzaghi")
        wait_until(lambda: '"terzaghi"' in self.driver.find_element(By.ID, "spec-text").get_attribute("value"), UI_TIMEOUT_S, "the example")
        wait_until(lambda: self.driver.find_element(By.ID, "validation-state").get_attribute("class").split()[-1] in ("valid", "idle"),
                   UI_TIMEOUT_S, "validation of the example")
        text = self.driver.find_element(By.ID, "spec-text").get_attribute("value")  # the example's own layout
        text = text.replace('"name": "terzaghi"', '"name": "terzaghi-short"').replace('"end": 51.0', '"end": 20.4')
        self.assertEqual(json.loads(text), short_terzaghi())
        self.set_editor(text)
        wait_until(lambda: self.driver.find_element(By.ID, "validation-state").get_attribute("class").split()[-1] in ("valid", "idle"),
                   UI_TIMEOUT_S, "validation of the spec")
        validated = "valid" in self.driver.find_element(By.ID, "validation-state").get_attribute("class").split()
        cost_shown = self.driver.find_element(By.ID, "validation-cost").text
        self.screenshot("submit")
        self.driver.find_element(By.ID, "submit-job").click()
        url = wait_until(lambda: "#/jobs/" in self.driver.current_url and self.driver.current_url, UI_TIMEOUT_S, "the job page")
        job_id = url.rsplit("/", 1)[1]
        doc = self.call("GET", f"/jobs/{job_id}")
        self.assertEqual(doc["name"], "terzaghi-short")
        if validated:  # the cost shown before submitting is the job's
            self.assertIn(f"steps\n{doc['cost']['steps']}", cost_shown)
        seen = set()

        def ended():
            seen.add(self.driver.find_element(By.CSS_SELECTOR, "#job-progress [role=progressbar]").get_attribute("aria-valuenow"))
            return self.driver.find_element(By.CSS_SELECTOR, "#job-status .badge").text.lower() == "successful"

        wait_until(ended, JOB_TIMEOUT_S, "the job to succeed in the page")
        self.assertEqual(self.driver.find_element(By.CSS_SELECTOR, "#job-progress [role=progressbar]").get_attribute("aria-valuenow"), "100")
        self.assertIn(job_id, self.driver.find_element(By.ID, "job-id").text)
        names = wait_until(lambda: [a.text for a in self.driver.find_elements(By.CSS_SELECTOR, "#result-files a.download")], UI_TIMEOUT_S, "the result files")
        for name in ("summary.json", "series.json", "series.csv", "snapshots.pvd", "snapshot_0000.vtu"):
            self.assertIn(name, names)
        self.assertIn('"terzaghi-short"', self.driver.find_element(By.ID, "job-spec").text)
        # the spec goes back to the submit page as it was sent
        self.css("#edit-job:enabled").click()
        wait_until(lambda: self.driver.current_url.endswith("#/submit"), UI_TIMEOUT_S, "the submit page")
        self.assertEqual(json.loads(self.css("#spec-text").get_attribute("value")), short_terzaghi())
        print(f"\n  progress values seen in the page: {sorted(seen, key=int)}", file=sys.stderr)

    def test_plot_of_the_series_has_a_line_per_particle(self):
        self.open(f"#/jobs/{self.jobs['terzaghi']}")
        paths = wait_until(lambda: self.driver.find_elements(By.CSS_SELECTOR, "#series-chart svg path[data-points]"), UI_TIMEOUT_S, "the chart")
        series = self.call("GET", f"/jobs/{self.jobs['terzaghi']}/results/series.json")
        self.assertEqual(len(paths), min(5, len(series["particles"])))
        for path in paths:
            self.assertEqual(int(path.get_attribute("data-points")), len(series["time"]))
            self.assertGreater(path.get_attribute("d").count("L"), len(series["time"]) // 2)
        Select(self.driver.find_element(By.ID, "series-field")).select_by_value("displacement")
        wait_until(lambda: "displacement" in self.driver.find_element(By.CSS_SELECTOR, "#series-chart svg").get_attribute("aria-label"),
                   UI_TIMEOUT_S, "the displacement chart")
        Select(self.driver.find_element(By.ID, "series-field")).select_by_value("pore_pressure")
        self.driver.execute_script("document.querySelector('.job-head').scrollIntoView()")
        self.screenshot("job")
        Select(self.driver.find_element(By.ID, "series-mode")).select_by_value("profile")
        dots = wait_until(lambda: self.driver.find_elements(By.CSS_SELECTOR, "#series-chart svg circle"), UI_TIMEOUT_S, "the profile")
        self.assertEqual(len(dots), len(series["particles"]))

    def test_profiles_and_consolidation_of_soft_clay(self):
        # Issue 44: profiles.json along its (vertical) line against depth
        # downward, consolidation.json, and the steps and time step that ran.
        job_id = self.jobs["soft-clay"]
        self.open(f"#/jobs/{job_id}")
        chart = self.css("#profile-chart svg[data-y-down='true']")
        profiles = self.call("GET", f"/jobs/{job_id}/results/profiles.json")
        paths = chart.find_elements(By.CSS_SELECTOR, "path[data-points]")
        self.assertEqual(len(paths), len(profiles["time"]))
        self.assertIn("depth below x = 4.938 m (m)", chart.get_attribute("aria-label"))
        self.assertIn("pore pressure (Pa)", chart.get_attribute("aria-label"))  # unit from /fields
        legend = self.driver.find_element(By.ID, "profile-legend").text
        self.assertIn("days", legend)
        self.assertIn("t = 0 s", legend)
        self.css("#consolidation-degree svg path[data-points]")
        self.assertIn("time (days, log)", self.driver.find_element(By.CSS_SELECTOR, "#consolidation-degree svg").get_attribute("aria-label"))
        doc = self.call("GET", f"/jobs/{job_id}")
        steps = self.driver.find_element(By.ID, "job-steps")
        self.assertEqual(steps.get_attribute("data-source"), "run")
        self.assertEqual(steps.text, str(doc["run"]["steps"]))
        self.assertNotEqual(doc["run"]["steps"], doc["cost"]["steps"])
        # A run shorter than one progress report: its mean step (end / steps).
        dt = self.driver.find_element(By.ID, "job-dt")
        self.assertEqual(dt.get_attribute("data-source"), "run")
        mean = doc["run"]["end_time"] / doc["run"]["steps"]
        self.assertAlmostEqual(float(dt.text.split()[0]), mean, delta=1e-3 * mean)
        self.driver.execute_script("document.getElementById('profiles-card').scrollIntoView()")
        if SCREENSHOTS:
            self.screenshot("job-profiles")

    def test_snapshot_view_draws_the_particles(self):
        self.open(f"#/jobs/{self.jobs['collapse']}")
        canvas = self.css("#snapshot-canvas[data-drawn]")
        self.assertEqual(int(canvas.get_attribute("data-drawn")), 400)
        Select(self.driver.find_element(By.ID, "snapshot-field")).select_by_value("velocity")
        coloured = self.driver.execute_script(
            "const c = document.getElementById('snapshot-canvas'); const d = c.getContext('2d')"
            ".getImageData(0, 0, c.width, c.height).data; let n = 0;"
            "for (let i = 0; i < d.length; i += 4) if (d[i + 3] > 0 && (d[i] < 200 || d[i + 2] < 200)) ++n; return n;")
        self.assertGreater(coloured, 2000, "particles and colour bar are drawn")
        info = self.driver.find_element(By.ID, "snapshot-info").text
        self.assertIn("400 particles", info)
        # the previous snapshot, drawn in the colour range of the last one
        self.driver.find_element(By.ID, "snapshot-keep-range").click()
        last = self.driver.find_element(By.ID, "snapshot-file").get_attribute("value")
        self.driver.find_element(By.CSS_SELECTOR, "button[title='previous snapshot']").click()
        wait_until(lambda: self.driver.find_element(By.ID, "snapshot-info").text != info, UI_TIMEOUT_S, "the previous snapshot")
        self.assertNotEqual(self.driver.find_element(By.ID, "snapshot-file").get_attribute("value"), last)
        self.assertTrue(self.driver.find_element(By.ID, "snapshot-info").text.endswith(info.split("range ")[1]), "the kept range")
        self.driver.find_element(By.CSS_SELECTOR, "button[title='next snapshot']").click()
        wait_until(lambda: self.driver.find_element(By.ID, "snapshot-info").text == info, UI_TIMEOUT_S, "the last snapshot again")
        self.driver.execute_script("document.getElementById('snapshot').scrollIntoView()")
        if SCREENSHOTS:
            self.driver.execute_script("window.scrollTo(0, 0)")
            self.screenshot("job-collapse")

    def test_running_job_shows_live_progress_and_can_be_cancelled(self):
        job_id = self.running_job()
        self.open(f"#/jobs/{job_id}")
        bar = "#job-progress [role=progressbar]"
        seen = set()

        def moving():
            seen.add(int(self.css(bar).get_attribute("aria-valuenow")))
            return len(seen - {0}) >= 2

        wait_until(moving, 60, "the progress to move twice")
        self.assertEqual(self.css("#job-head").get_attribute("data-live"), "events", "progress from the event stream")
        self.assertEqual(self.css("#job-status .badge").text.lower(), "running")
        self.assertTrue(self.css("#cancel-job").is_enabled())
        self.screenshot("job-running")
        self.css("#cancel-job").click()
        self.css("dialog[open] #confirm-yes").click()
        # a server with POST /jobs/{id}/cancel dismisses the job; an older one
        # answers 404 and the page says that Delete is the way
        wait_until(lambda: self.css("#job-status .badge").text.lower() == "dismissed"
                   or "no separate cancel" in self.css("#action-message").text, UI_TIMEOUT_S, "the cancel outcome")

    def test_vtu_reader_gives_the_values_of_the_file(self):
        name = "snapshot_0003.vtu"
        xml = urllib.request.urlopen(urllib.request.Request(
            f"{self.service.url}/jobs/{self.jobs['collapse']}/results/{name}",
            headers={"Authorization": f"Bearer {TOKEN}"} if TOKEN else {}), timeout=30).read().decode()
        raw = base64.b64decode(re.search(r'Name="velocity"[^>]*format="binary">\s*([^<\s]+)', xml).group(1))
        (count,) = struct.unpack_from("<Q", raw)
        expected = struct.unpack_from(f"<{count // 8}d", raw, 8)
        self.open("#/jobs")
        ascii_doc = ('<VTKFile type="UnstructuredGrid" byte_order="LittleEndian"><UnstructuredGrid><Piece NumberOfPoints="2">'
                     '<PointData><DataArray type="Float64" Name="p" format="ascii">1.5 -2e3</DataArray></PointData>'
                     '<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1 2 0</DataArray></Points>'
                     '</Piece></UnstructuredGrid></VTKFile>')
        got = self.driver.execute_async_script(
            "const [xml, ascii, done] = arguments; import('/ui/vtu.js').then((m) => {"
            "  const v = m.parse_vtu(xml), a = m.parse_vtu(ascii);"
            "  done({count: v.count, velocity: Array.from(v.fields.find((f) => f.name === 'velocity').values),"
            "        ascii: Array.from(a.fields[0].values), points: Array.from(a.points)});"
            "}).catch((e) => done({error: String(e)}))", xml, ascii_doc)
        self.assertNotIn("error", got)
        self.assertEqual(got["count"], 400)
        self.assertEqual(got["velocity"], list(expected))
        self.assertEqual(got["ascii"], [1.5, -2000.0])
        self.assertEqual(got["points"], [0, 0, 0, 1, 2, 0])

    def test_cancel_and_delete_ask_first(self):
        job_id = self.submit(example("geostatic"))
        self.wait_job(job_id)
        self.open(f"#/jobs/{job_id}")
        wait_until(lambda: self.driver.find_element(By.CSS_SELECTOR, "#job-status .badge").text.lower() == "successful", UI_TIMEOUT_S, "status")
        self.assertFalse(self.driver.find_element(By.ID, "cancel-job").is_enabled(), "a finished job cannot be cancelled")
        self.driver.find_element(By.ID, "delete-job").click()
        self.css("dialog[open] #confirm-no").click()  # keep it
        self.assertEqual(self.call("GET", f"/jobs/{job_id}")["status"], "successful")
        self.driver.find_element(By.ID, "delete-job").click()
        self.css("dialog[open] #confirm-yes").click()
        wait_until(lambda: self.driver.find_element(By.CSS_SELECTOR, "#job-status .badge").text.lower() == "dismissed", UI_TIMEOUT_S, "dismissed")
        self.assertEqual(self.call("GET", f"/jobs/{job_id}")["status"], "dismissed")


    def test_ensemble_page_shows_samples_fan_plot_and_histogram(self):
        spec = example("bar-vibration")
        spec["time"]["end"] = min(spec["time"]["end"], 0.5)
        spec.get("output", {}).pop("snapshots", None)
        body = {"spec": spec, "samples": 24, "seed": 43,
                "vary": [{"path": "/materials/bar/youngs_modulus",
                          "distribution": {"lognormal": {"mean": spec["materials"]["bar"]["youngs_modulus"],
                                                         "cov": 0.3}}}]}
        eid = self.call("POST", "/ensembles", json.dumps(body).encode())["ensembleID"]
        wait_until(lambda: self.call("GET", f"/ensembles/{eid}")["status"] in ("successful", "failed", "dismissed"),
                   JOB_TIMEOUT_S, f"ensemble {eid} to end")
        self.open(f"#/ensembles/{eid}")
        wait_until(lambda: len(self.driver.find_elements(By.CSS_SELECTOR, "#sample-table tbody tr")) == 24,
                   UI_TIMEOUT_S, "a row per sample")
        rows = self.driver.find_elements(By.CSS_SELECTOR, "#sample-table tbody tr")
        self.assertTrue(all(r.get_attribute("data-status") == "successful" for r in rows))
        # the fan plot: a 5-95 % band and the median and mean lines
        band = self.css("#ensemble-fan svg path.band")
        self.assertEqual(band.get_attribute("data-label"), "5–95 %")
        labels = {p.get_attribute("data-label") for p in
                  self.driver.find_elements(By.CSS_SELECTOR, "#ensemble-fan svg path[data-points]")}
        self.assertEqual(labels, {"median", "mean"})
        # the histogram counts every successful sample
        hist = self.css("#ensemble-histogram svg.histogram rect[data-count]")
        counts = sum(int(r.get_attribute("data-count")) for r in
                     self.driver.find_elements(By.CSS_SELECTOR, "#ensemble-histogram svg.histogram rect[data-count]"))
        self.assertTrue(hist)
        self.assertEqual(counts, 24)
        self.screenshot("ensemble")

if __name__ == "__main__":
    unittest.main(verbosity=2)
