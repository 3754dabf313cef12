"""Starts what the browser tests talk to, and a headless Chromium.

- HMPM_URL set: the tests use that server as it is (nothing is started).
- Otherwise: hmpm-server from $HMPM_BIN_DIR (default $HMPM_BUILD_DIR/bin,
  default build/bin) on a free loopback port, with a fresh database; with
  HMPM_UI_PROXY=1, tests/browser/dev_proxy.py in front of it (for servers
  that do not serve /ui yet; it runs `hmpm validate -` for POST /validate).
- HMPM_TOKEN set: the server started here requires it, and the tests send it
  (the page reads it from localStorage, as the header's Token field stores it).
"""

import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
START_TIMEOUT_S = 30


def _first_line(proc, what):
    """The URL from the first stdout line `listening on http://...`."""
    box = {}

    def read():
        box["line"] = proc.stdout.readline()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    reader.join(START_TIMEOUT_S)
    line = box.get("line", "")
    if not line.startswith("listening on "):
        proc.kill()
        raise RuntimeError(f"{what} did not start: {line!r}")
    return line.split("listening on ", 1)[1].strip()


class Service:
    """The base URL the tests use, and the processes behind it."""

    def __init__(self):
        self.procs = []
        self.logs = []
        self.tmp = None
        self.url = os.environ.get("HMPM_URL", "").rstrip("/")
        if self.url:
            return
        bin_dir = Path(os.environ.get("HMPM_BIN_DIR") or Path(os.environ.get("HMPM_BUILD_DIR", REPO / "build")) / "bin")
        server = bin_dir / "hmpm-server"
        if not server.exists():
            raise RuntimeError(f"no {server}: build it, or set HMPM_BIN_DIR / HMPM_BUILD_DIR / HMPM_URL")
        self.tmp = tempfile.mkdtemp(prefix="hmpm-ui-test-")
        proc = subprocess.Popen(
            [str(server), "--host", "127.0.0.1", "--port", "0", "--db", f"{self.tmp}/db.sqlite",
             "--data-dir", f"{self.tmp}/results", "--workers", "2"]
            + (["--token", os.environ["HMPM_TOKEN"]] if os.environ.get("HMPM_TOKEN") else []),
            stdout=subprocess.PIPE, stderr=self._log("server.log"), text=True)
        self.procs.append(proc)
        self.url = _first_line(proc, "hmpm-server")
        if os.environ.get("HMPM_UI_PROXY") == "1":
            hmpm = bin_dir / "hmpm"
            proxy = subprocess.Popen(
                [sys.executable, str(REPO / "tests/browser/dev_proxy.py"), "--upstream", self.url,
                 "--hmpm", str(hmpm)],
                stdout=subprocess.PIPE, stderr=self._log("proxy.log"), text=True)
            self.procs.append(proxy)
            self.url = _first_line(proxy, "dev_proxy.py")

    def _log(self, name):
        log = open(f"{self.tmp}/{name}", "w")
        self.logs.append(log)
        return log

    def stop(self):
        for log in self.logs:
            log.close()
        for proc in reversed(self.procs):
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(10)
            if proc.stdout:
                proc.stdout.close()
        if self.tmp:
            shutil.rmtree(self.tmp, ignore_errors=True)


def chromium(width=1360, height=900):
    """A headless Chromium driven by Debian's chromedriver."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service as DriverService

    options = webdriver.ChromeOptions()
    options.binary_location = os.environ.get("CHROMIUM", "/usr/bin/chromium")
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
                f"--window-size={width},{height}", "--force-device-scale-factor=1",
                "--no-first-run", "--disable-extensions", "--disable-background-networking"):
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})  # console errors, read by the tests
    driver = webdriver.Chrome(service=DriverService(os.environ.get("CHROMEDRIVER", "/usr/bin/chromedriver")), options=options)
    driver.set_page_load_timeout(30)
    driver.set_script_timeout(30)
    return driver


def wait_until(predicate, timeout_s, what):
    """Calls predicate until it returns something truthy; fails after timeout_s."""
    deadline = time.monotonic() + timeout_s
    last = None
    while time.monotonic() < deadline:
        try:
            value = predicate()
            if value:
                return value
        except Exception as exc:  # stale elements while the page redraws
            last = exc
        time.sleep(0.1)
    raise AssertionError(f"timed out after {timeout_s} s waiting for {what}" + (f" ({last})" if last else ""))
