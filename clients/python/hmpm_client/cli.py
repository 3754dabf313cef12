"""The `python3 -m hmpm_client` command line.

    python3 -m hmpm_client --url URL submit SPEC.json [--wait] [--download DIR]
    python3 -m hmpm_client --url URL status ID | list [--status S] [--name N] [--limit N]
    python3 -m hmpm_client --url URL wait ID | results ID | download ID DIR | log ID
    python3 -m hmpm_client --url URL cancel ID     # stop a queued/running job, keep its files
    python3 -m hmpm_client --url URL delete ID     # dismiss a job and delete its files
    python3 -m hmpm_client --url URL plot ID|DIR --field pore_pressure [--out FILE.png] [--profile LINE | --consolidation]
    python3 -m hmpm_client --url URL ensemble submit REQUEST.json [--wait] [--download DIR]
    python3 -m hmpm_client --url URL ensemble wait ID | stats ID [--json] | download ID DIR
    python3 -m hmpm_client --url URL ensemble status ID | list | cancel ID | delete ID

`plot` takes a job id, or a local folder holding series.json (what
`download` or `hmpm run --out` wrote), so no service is needed for it.

An ensemble request is {"spec", "samples", "seed", "vary"} (docs/api.md,
Ensembles); `ensemble stats` prints the figures at the last time.

Exit status: 0 success (for submit --wait and wait: the job succeeded);
1 the service refused the request or could not be reached; 2 bad usage or a
refused job spec (each JSON path and message on stderr); 3 the job failed or
was dismissed (the reason on stderr); 4 matplotlib is missing (plot).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path
from typing import Any, Dict, List, Optional

from .client import DEFAULT_URL, Client, Job
from .errors import HmpmError

EXIT_OK, EXIT_ERROR, EXIT_INVALID, EXIT_JOB_FAILED, EXIT_NO_MATPLOTLIB = 0, 1, 2, 3, 4
PROG = "hmpm_client"


def _err(msg: str) -> None:
    print(f"{PROG}: {msg}", file=sys.stderr)


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python3 -m hmpm_client",
        description="Submit, follow and download hmpm jobs.",
        epilog="Exit status: 0 success; 1 request refused or service unreachable; 2 usage error or "
               "invalid job spec (each JSON path on stderr); 3 job failed or dismissed; 4 matplotlib missing.",
    )
    p.add_argument("--url", default=os.environ.get("HMPM_URL") or DEFAULT_URL,
                   help=f"service URL (default: $HMPM_URL or {DEFAULT_URL})")
    p.add_argument("--token", default=None, help="bearer token (default: $HMPM_TOKEN)")
    p.add_argument("--timeout", type=float, default=None,
                   help="give up waiting for a job after this many seconds (default: no limit)")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    s = sub.add_parser("submit", help="submit a job spec (JSON file, or - for stdin)")
    s.add_argument("spec", metavar="SPEC")
    s.add_argument("--wait", action="store_true", help="show progress and wait until the job ends")
    s.add_argument("--download", metavar="DIR", help="then download every result file into DIR (implies --wait)")
    s.add_argument("--idempotency-key", metavar="KEY", help="repeat-safe submission key")
    s.add_argument("--quiet", "-q", action="store_true", help="no progress bar")

    s = sub.add_parser("status", help="print a job's status document")
    s.add_argument("id")

    s = sub.add_parser("wait", help="show progress and wait until a job ends")
    s.add_argument("id")
    s.add_argument("--quiet", "-q", action="store_true", help="no progress bar")

    s = sub.add_parser("list", help="list jobs")
    s.add_argument("--status", metavar="S[,S...]",
                   help="only these states: accepted, running, successful, failed, dismissed")
    s.add_argument("--name", help="only jobs of this name (the spec's \"name\")")
    s.add_argument("--limit", type=int)
    s.add_argument("--json", action="store_true", help="print the status documents as JSON")

    s = sub.add_parser("cancel", help="stop a queued or running job (its files stay; a finished job is left as it is)")
    s.add_argument("id")

    s = sub.add_parser("delete", help="dismiss a job and delete its result files")
    s.add_argument("id")

    s = sub.add_parser("log", help="print a job's log")
    s.add_argument("id")

    s = sub.add_parser("results", help="list a finished job's result files")
    s.add_argument("id")

    s = sub.add_parser("download", help="download a finished job's result files into DIR")
    s.add_argument("id")
    s.add_argument("dir")

    s = sub.add_parser("plot", help="plot the time histories of the series particles")
    s.add_argument("id", metavar="ID|DIR", help="a job id, or a local result folder with series.json")
    s.add_argument("--field", default="pore_pressure", help="series field (default: pore_pressure)")
    s.add_argument("--out", metavar="FILE.png", help="output file (default: ID-FIELD.png)")
    s.add_argument("--profile", metavar="LINE", type=int,
                   help="plot line LINE of profiles.json (the field along the line, a curve per "
                        "time) instead of the series")
    s.add_argument("--consolidation", action="store_true",
                   help="plot consolidation.json (the average degree of consolidation and the "
                        "average excess pore pressure over time) instead of the series")

    e = sub.add_parser("ensemble", help="ensembles of jobs: submit, wait, stats, download, ...")
    esub = e.add_subparsers(dest="ensemble_command", metavar="ACTION")
    esub.required = True
    s = esub.add_parser("submit", help="submit an ensemble request (JSON file, or - for stdin)")
    s.add_argument("request", metavar="REQUEST")
    s.add_argument("--wait", action="store_true", help="wait until every sample has ended")
    s.add_argument("--download", metavar="DIR",
                   help="then download samples.json and statistics.json into DIR (implies --wait)")
    s.add_argument("--idempotency-key", metavar="KEY", help="repeat-safe submission key")
    s.add_argument("--quiet", "-q", action="store_true", help="no progress lines")
    for action, text in (("status", "print an ensemble's status document"),
                         ("wait", "wait until every sample of an ensemble has ended"),
                         ("cancel", "cancel every sample not yet ended"),
                         ("delete", "dismiss every sample and delete its files")):
        s = esub.add_parser(action, help=text)
        s.add_argument("id")
        if action == "wait":
            s.add_argument("--quiet", "-q", action="store_true", help="no progress lines")
    s = esub.add_parser("stats", help="the statistics at the last time (mean, std, p05, p50, p95)")
    s.add_argument("id")
    s.add_argument("--json", action="store_true", help="print the whole statistics.json")
    s = esub.add_parser("download", help="download samples.json and statistics.json into DIR")
    s.add_argument("id")
    s.add_argument("dir")
    s = esub.add_parser("list", help="list ensembles")
    s.add_argument("--status", metavar="S[,S...]")
    s.add_argument("--limit", type=int)
    return p


def _print_json(doc: Any) -> None:
    print(json.dumps(doc, indent=2, sort_keys=False))


def _status_line(doc: Dict[str, Any]) -> str:
    progress = doc.get("progress")
    pct = f"{float(progress):3.0f}%" if isinstance(progress, (int, float)) else "  ?%"
    msg = str(doc.get("message") or "")
    name = str(doc.get("name") or "-")
    return (f"{doc.get('jobID', '?')}  {name:<20} {str(doc.get('status', '?')):<10} {pct}  "
            f"{doc.get('created', '')}  {msg}")


def _finish(job: Job, doc: Dict[str, Any]) -> int:
    status = doc.get("status")
    if status == "successful":
        return EXIT_OK
    reason = doc.get("reason") or doc.get("message") or "no reason given"
    if doc.get("message") and doc.get("reason") and doc["message"] not in doc["reason"]:
        reason = f"{doc['message']}: {doc['reason']}"
    _err(f"job {job.id} {status}: {reason}")
    return EXIT_JOB_FAILED


def _wait(job: Job, args) -> Dict[str, Any]:
    return job.wait(progress=not getattr(args, "quiet", False), timeout=args.timeout)


def _download(job: Job, directory: str) -> None:
    paths = job.download(directory)
    print(f"{PROG}: downloaded {len(paths)} files to {directory} (sha256 verified)", file=sys.stderr)


def _input(name: str) -> Any:
    """What to submit: stdin's bytes for "-", else the file's path (None,
    said on stderr, when there is no such file)."""
    if name == "-":
        return sys.stdin.buffer.read()
    if not Path(name).is_file():
        _err(f"{name}: no such file")
        return None
    return name


def _submitted(handle: Any, args) -> bool:
    """Prints a new job's or ensemble's id (stdout) and warnings (stderr);
    whether to wait for it."""
    print(handle.id, flush=True)
    for w in handle.warnings:
        _err(f"warning: {w.get('path', '')}: {w.get('message', '')}")
    return bool(args.wait or args.download)


def cmd_submit(client: Client, args) -> int:
    spec = _input(args.spec)
    if spec is None:
        return EXIT_INVALID
    job = client.submit(spec, idempotency_key=args.idempotency_key)
    if not _submitted(job, args):
        return EXIT_OK
    doc = _wait(job, args)
    code = _finish(job, doc)
    if args.download:
        if code == EXIT_OK:
            _download(job, args.download)
        else:
            # A failed job may still have a summary.json with the reason.
            try:
                _download(job, args.download)
            except HmpmError:
                pass
    return code


def cmd_status(client: Client, args) -> int:
    _print_json(client.job(args.id).status())
    return EXIT_OK


def cmd_wait(client: Client, args) -> int:
    job = client.job(args.id)
    return _finish(job, _wait(job, args))


def cmd_list(client: Client, args) -> int:
    docs = client.jobs(status=args.status, limit=args.limit, name=args.name)
    if args.json:
        _print_json(docs)
    else:
        for d in docs:
            print(_status_line(d))
    return EXIT_OK


def cmd_cancel(client: Client, args) -> int:
    try:
        doc = client.job(args.id).cancel()
    except HmpmError as e:
        if e.status == 409:
            ended = (e.problem or {}).get("jobStatus") or "ended"
            _err(f"job {args.id} had already ended ({ended}): nothing was changed, its results "
                 f"are intact (to delete them: delete {args.id})")
            return EXIT_ERROR
        raise
    print(_status_line(doc))
    return EXIT_OK


def cmd_delete(client: Client, args) -> int:
    print(_status_line(client.job(args.id).delete()))
    return EXIT_OK


def cmd_log(client: Client, args) -> int:
    sys.stdout.write(client.job(args.id).log())
    return EXIT_OK


def cmd_results(client: Client, args) -> int:
    for f in client.job(args.id).results():
        print(f"{f.get('size', '?'):>12}  {f.get('sha256', '')}  {f.get('name')}")
    return EXIT_OK


def cmd_download(client: Client, args) -> int:
    _download(client.job(args.id), args.dir)
    return EXIT_OK


def _field_units(client: Client) -> dict:
    """The fields' units from the service (GET /fields); {} with a note on
    stderr when it cannot be asked (a local folder plotted offline)."""
    try:
        return client.field_units()
    except (HmpmError, OSError, ValueError) as e:
        _err(f"note: the field units come from the service's /fields, which could not be read "
             f"({e}): the value axes carry no unit")
        return {}


def cmd_plot(client: Client, args) -> int:
    from .plot import MatplotlibMissing, plot_consolidation, plot_profile, plot_series
    local = Path(args.id)
    label = local.name if local.is_dir() else args.id
    profile = args.profile is not None
    if profile and args.consolidation:
        _err("give --profile or --consolidation, not both")
        return EXIT_ERROR
    if args.consolidation:
        name, section = "consolidation.json", "output.consolidation"
        out = Path(args.out or f"{label}-consolidation.png")
    elif profile:
        name, section = "profiles.json", "output.profiles"
        out = Path(args.out or f"{label}-{args.field}-profile{args.profile}.png")
    else:
        name, section = "series.json", "output.series"
        out = Path(args.out or f"{label}-{args.field}.png")
    try:
        if local.is_dir():
            path = local / name
            if not path.is_file():
                _err(f"{local}: no {name} in this folder (did the spec ask for {section}?)")
                return EXIT_ERROR
            doc = json.loads(path.read_text())
            title = f"{local}: {args.field}"
        else:
            job = client.job(args.id)
            doc = json.loads(job.read_result(name)) if name != "series.json" else job.series()
            title = f"job {args.id}: {args.field}"
        if args.consolidation:
            plot_consolidation(doc, out, title=title.split(": ")[0] + ": degree of consolidation")
        elif profile:
            plot_profile(doc, args.field, out, line=args.profile, title=title + f", profile {args.profile}",
                         units=_field_units(client))
        else:
            plot_series(doc, args.field, out, title=title, units=_field_units(client))
    except MatplotlibMissing as e:
        _err(str(e))
        return EXIT_NO_MATPLOTLIB
    except ValueError as e:
        _err(str(e))
        return EXIT_ERROR
    print(out)
    return EXIT_OK


def _ensemble_finish(doc: Dict[str, Any]) -> int:
    if doc.get("status") == "successful":
        return EXIT_OK
    _err(f"ensemble {doc.get('ensembleID')} {doc.get('status')}: {doc.get('counts')}")
    return EXIT_JOB_FAILED


def cmd_ensemble(client: Client, args) -> int:
    from .ensemble import final_statistics, format_status
    action = args.ensemble_command
    if action == "submit":
        request = _input(args.request)
        if request is None:
            return EXIT_INVALID
        ens = client.submit_ensemble(request, idempotency_key=args.idempotency_key)
        if not _submitted(ens, args):
            return EXIT_OK
        code = _ensemble_finish(ens.wait(progress=not args.quiet, timeout=args.timeout))
        if args.download:
            paths = ens.download(args.download)
            _err(f"downloaded {len(paths)} files to {args.download} (sha256 verified)")
        return code
    if action == "list":
        for d in client.ensembles(status=args.status, limit=args.limit):
            print(format_status(d))
        return EXIT_OK
    ens = client.ensemble(args.id)
    if action == "status":
        _print_json(ens.status())
    elif action == "wait":
        return _ensemble_finish(ens.wait(progress=not args.quiet, timeout=args.timeout))
    elif action == "cancel":
        print(format_status(ens.cancel()))
    elif action == "delete":
        print(format_status(ens.delete()))
    elif action == "stats":
        stats = ens.statistics()
        if args.json:
            _print_json(stats)
            return EXIT_OK
        times = stats.get("time") or []
        print(f"{stats.get('samples', 0)} successful samples; figures at t = "
              f"{times[-1] if times else '?'} s")
        print(f"{'particle':>8}  {'field':<20} {'mean':>12} {'std':>12} {'p05':>12} {'p50':>12} {'p95':>12}")
        for row in final_statistics(stats):
            name = row["field"] + (f"[{row['component']}]" if row["component"] is not None else "")
            cells = " ".join(f"{row[k]:>12.5g}" if isinstance(row[k], (int, float)) else f"{'-':>12}"
                             for k in ("mean", "std", "p05", "p50", "p95"))
            print(f"{row['particle']!s:>8}  {name:<20} {cells}")
    elif action == "download":
        paths = ens.download(args.dir)
        _err(f"downloaded {len(paths)} files to {args.dir} (sha256 verified)")
    return EXIT_OK


COMMANDS = {
    "submit": cmd_submit, "status": cmd_status, "wait": cmd_wait, "list": cmd_list,
    "cancel": cmd_cancel, "delete": cmd_delete, "log": cmd_log, "results": cmd_results, "download": cmd_download, "plot": cmd_plot,
    "ensemble": cmd_ensemble,
}


def main(argv: Optional[List[str]] = None) -> int:
    args = _parser().parse_args(argv)
    client = Client(args.url, token=args.token)
    try:
        return COMMANDS[args.command](client, args)
    except HmpmError as e:
        if e.errors:
            _err(f"job spec refused: {e}")
            return EXIT_INVALID
        _err(str(e))
        return EXIT_ERROR
    except TimeoutError as e:
        _err(str(e))
        return EXIT_ERROR
    except KeyboardInterrupt:
        _err("interrupted (the job keeps running on the service; cancel it with: cancel ID)")
        return 130
    except OSError as e:
        _err(str(e))
        return EXIT_ERROR
