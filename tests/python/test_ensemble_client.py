"""The Python client's ensembles against a real hmpm-server: the library
(submit_ensemble, wait, samples, statistics, download, jobs) and the
`ensemble submit/wait/stats/download` commands, with statistics.json checked
against the samples' own series.json as this client downloads them."""

from __future__ import annotations

import hashlib
import json
import statistics as pystats
import unittest

from hmpm_client import Client, Ensemble, HmpmError

from tests.python.support import LiveServerCase, bar_spec, run_cli

SAMPLES = 5


def request(seed: int = 11, samples: int = SAMPLES) -> dict:
    spec = bar_spec(end=0.2)
    spec["output"].pop("snapshots", None)
    return {"spec": spec, "samples": samples, "seed": seed,
            "vary": [{"path": "/materials/bar/youngs_modulus",
                      "distribution": {"lognormal": {"mean": 10.0, "cov": 0.2}}}]}


class EnsembleClientTest(LiveServerCase):
    def client(self) -> Client:
        return Client(self.server.url)

    def test_library_submit_wait_statistics_and_download(self):
        client = self.client()
        ens = client.submit_ensemble(request())
        self.assertIsInstance(ens, Ensemble)
        self.assertEqual(len(ens.doc["jobs"]), SAMPLES)
        doc = ens.wait(progress=False, timeout=60)
        self.assertEqual(doc["status"], "successful")
        self.assertEqual(doc["counts"]["successful"], SAMPLES)
        self.assertIn(ens.id, [d["ensembleID"] for d in client.ensembles()])

        samples = ens.samples()
        moduli = [s["values"]["/materials/bar/youngs_modulus"] for s in samples["samples"]]
        self.assertEqual(len(set(moduli)), SAMPLES)
        # statistics.json against the samples' series, recomputed here with
        # Python's statistics module (sample std; the median is p50).
        stats = ens.statistics()
        series = [job.series() for job in ens.jobs()]
        last = len(stats["time"]) - 1
        for p in range(len(series[0]["particles"])):
            values = [s["particles"][p]["velocity"][last][0] for s in series]
            fig = stats["particles"][p]["velocity"]
            self.assertAlmostEqual(fig["mean"][last][0], pystats.fmean(values), delta=1e-12)
            self.assertAlmostEqual(fig["std"][last][0], pystats.stdev(values), delta=1e-12)
            self.assertAlmostEqual(fig["p50"][last][0], pystats.median(values), delta=1e-12)
            self.assertLessEqual(fig["p05"][last][0], fig["p50"][last][0])
            self.assertLessEqual(fig["p50"][last][0], fig["p95"][last][0])

        paths = ens.download(self.tmp / "out")
        self.assertEqual(sorted(p.name for p in paths), ["samples.json", "statistics.json"])
        manifest = {f["name"]: f for f in ens.results()}
        for p in paths:
            self.assertEqual(hashlib.sha256(p.read_bytes()).hexdigest(), manifest[p.name]["sha256"])
        self.assertEqual(json.loads((self.tmp / "out" / "statistics.json").read_text()), stats)

    def test_a_refused_request_names_its_paths(self):
        bad = request()
        bad["vary"][0]["path"] = "/materials/bar/nothing"
        with self.assertRaises(HmpmError) as caught:
            self.client().submit_ensemble(bad)
        self.assertEqual(caught.exception.status, 400)
        self.assertIn("/vary/0/path", [e["path"] for e in caught.exception.errors])

    def test_commands_submit_wait_stats_download(self):
        path = self.tmp / "request.json"
        path.write_text(json.dumps(request(seed=12, samples=3)))
        url = ["--url", self.server.url]
        run = run_cli(url + ["ensemble", "submit", str(path), "--wait", "--download",
                             str(self.tmp / "dl"), "-q"])
        self.assertEqual(run.returncode, 0, run.stderr)
        eid = run.stdout.strip().splitlines()[0]
        self.assertTrue((self.tmp / "dl" / "statistics.json").is_file())
        run = run_cli(url + ["ensemble", "wait", eid, "-q"])
        self.assertEqual(run.returncode, 0, run.stderr)
        run = run_cli(url + ["ensemble", "stats", eid])
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertIn("3 successful samples", run.stdout)
        self.assertIn("velocity[0]", run.stdout)
        run = run_cli(url + ["ensemble", "stats", eid, "--json"])
        self.assertEqual(json.loads(run.stdout)["samples"], 3)
        run = run_cli(url + ["ensemble", "download", eid, str(self.tmp / "again")])
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertEqual((self.tmp / "again" / "samples.json").read_bytes(),
                         (self.tmp / "dl" / "samples.json").read_bytes())
        bad = request()
        bad["samples"] = 0
        path.write_text(json.dumps(bad))
        run = run_cli(url + ["ensemble", "submit", str(path)])
        self.assertEqual(run.returncode, 2, run.stderr)
        self.assertIn("/samples", run.stderr)


if __name__ == "__main__":
    unittest.main()
