"""hmpm_client: a standard-library Python client for the hmpm job service.

    from hmpm_client import Client, HmpmError
    job = Client("http://127.0.0.1:8080").submit("examples/terzaghi.json")
    job.wait()
    job.download("out/")

From the shell: `python3 -m hmpm_client --url URL submit SPEC --wait
--download DIR` (see `python3 -m hmpm_client --help`).
"""

from .client import DEFAULT_URL, TERMINAL_STATUSES, Client, Job
from .ensemble import Ensemble
from .errors import HmpmError

__all__ = ["Client", "Job", "Ensemble", "HmpmError", "TERMINAL_STATUSES", "DEFAULT_URL"]
__version__ = "0.1.0"
