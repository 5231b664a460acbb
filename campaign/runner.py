"""Monte-Carlo campaigns on Ray: tasks, per-trial seeds, a resumable result file.

A campaign is a list of :class:`Task`: a trial function named by ``kind`` (an entry of
:data:`campaign.trials.TRIALS`), its JSON parameters, and a range of trial indices. Each
trial draws its random numbers from ``numpy.random.default_rng([seed, group, trial])``:
``seed`` the campaign's, ``group`` a stable hash of (kind, params), ``trial`` the trial's
index. So a trial's numbers do not depend on which task holds it, which worker runs it or in
which order tasks finish: the same seed gives the same results with 1 or N workers.

Results go to a JSON-lines file, one line per finished task ``{"key", "task", "result"}``,
written and flushed as each task ends. Running the same campaign again reads the file and
runs only the tasks not in it (an interrupted campaign resumes where it stopped; a last line
cut by a kill is dropped). Lines of other campaigns (other seed, other tasks) are kept and
ignored.

Ray: a local Ray with ``workers`` CPUs is started on demand (and stopped at the end);
``address`` (or the ``RAY_ADDRESS`` environment variable) attaches to an existing cluster
instead, whose nodes must have this project installed. A Ray already initialised in this
process is used as it is. At most ``workers`` tasks are in flight at once.
"""

from __future__ import annotations

import hashlib
import json
import os
import socket
import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

Result = dict[str, Any]
"""A task's result: JSON values; numbers and lists of numbers add up across tasks."""


class CampaignError(ValueError):
    """A campaign that cannot run (bad input, unreachable Ray): one line for the user."""


@dataclass(frozen=True)
class Task:
    """Trials ``first .. first + count - 1`` of trial function ``kind`` with ``params``."""

    kind: str
    params: dict[str, Any] = field(hash=False)
    first: int
    count: int

    def group(self) -> int:
        """Stable 63-bit hash of (kind, params): the middle word of every trial's seed."""
        text = json.dumps([self.kind, self.params], sort_keys=True)
        return int.from_bytes(hashlib.sha256(text.encode()).digest()[:8], "big") >> 1

    def key(self, seed: int) -> str:
        """Identity of the task's result in the result file, for campaign seed ``seed``."""
        text = json.dumps([seed, self.kind, self.params, self.first, self.count],
                          sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:24]

    def as_json(self) -> dict[str, Any]:
        return {"kind": self.kind, "params": self.params, "first": self.first,
                "count": self.count}


def split(kind: str, params: dict[str, Any], trials: int, per_task: int) -> list[Task]:
    """``trials`` trials of (kind, params) as tasks of at most ``per_task`` trials."""
    if trials < 1:
        raise CampaignError(f"trials: must be at least 1, got {trials}")
    return [Task(kind, params, lo, min(per_task, trials - lo))
            for lo in range(0, trials, per_task)]


def merge(results: Iterable[Result]) -> Result:
    """Element-wise sum of task results (numbers and equal-length lists of numbers)."""
    out: Result = {}
    for r in results:
        for k, v in r.items():
            if k not in out:
                out[k] = list(v) if isinstance(v, list) else v
            elif isinstance(v, list):
                out[k] = [a + b for a, b in zip(out[k], v, strict=True)]
            else:
                out[k] += v
    return out


def execute(kind: str, params: dict[str, Any], first: int, count: int, seed: int,
            group: int) -> Result:
    """Run one task in this process (what a Ray worker runs)."""
    from campaign.trials import TRIALS
    return TRIALS[kind](params, range(first, first + count), seed, group)


def read_results(path: Path) -> dict[str, Result]:
    """key -> result of every complete line of the result file (none when it is missing);
    a last line cut short by a kill is removed from the file."""
    if not path.exists():
        return {}
    data = path.read_bytes()
    good_end = data.rfind(b"\n") + 1
    if good_end < len(data):            # a partial last line: drop it so appends stay valid
        with open(path, "r+b") as f:
            f.truncate(good_end)
    out = {}
    for line in data[:good_end].splitlines():
        try:
            rec = json.loads(line)
            out[rec["key"]] = rec["result"]
        except (ValueError, KeyError, TypeError):
            raise CampaignError(f"{path}: not a campaign result file (line {line[:60]!r})"
                                ) from None
    return out


def check_address(address: str) -> None:
    """CampaignError unless a TCP connection to the Ray address ``host:port`` (optionally
    ``ray://host:port``) opens within 3 s ("auto" and "local" are left to Ray)."""
    if address in ("auto", "local"):
        return
    hostport = address.split("://", 1)[-1]
    host, _, port = hostport.rpartition(":")
    if not host or not port.isdigit():
        raise CampaignError(f"--ray-address: expected HOST:PORT, got {address!r}")
    try:
        socket.create_connection((host, int(port)), timeout=3.0).close()
    except OSError as exc:
        raise CampaignError(f"--ray-address: no Ray cluster at {address} "
                            f"({exc.strerror or exc})") from None


@dataclass
class RaySession:
    """Ray for one campaign: attach (address), reuse (already initialised) or start a local
    one with ``workers`` CPUs; :meth:`close` stops only a Ray this session started."""

    workers: int
    address: str | None = None
    started: bool = False

    def open(self) -> None:
        import ray
        if ray.is_initialized():
            return
        address = self.address or os.environ.get("RAY_ADDRESS") or None
        try:
            if address:
                check_address(address)
                ray.init(address=address, logging_level="ERROR", log_to_driver=False)
            else:
                _export_source_path()
                ray.init(num_cpus=self.workers, include_dashboard=False,
                         logging_level="ERROR", log_to_driver=False)
        except CampaignError:
            raise
        except (ConnectionError, RuntimeError, ValueError) as exc:
            raise CampaignError(f"Ray: {str(exc).splitlines()[0]}") from None
        self.started = True

    def close(self) -> None:
        if self.started:
            import ray
            ray.shutdown()
            self.started = False


def _export_source_path() -> None:
    """Put the folder this package is imported from first on PYTHONPATH, which the local
    Ray's workers inherit: they run the driver's code, not another installed copy."""
    root = str(Path(__file__).resolve().parents[1])
    paths = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    if root not in paths:
        os.environ["PYTHONPATH"] = os.pathsep.join([root, *paths])


def run(tasks: list[Task], seed: int, out: Path, *, workers: int = 2,
        address: str | None = None, desc: str = "campaign", progress: bool | None = None,
        on_result: Callable[[Task, Result], None] | None = None) -> dict[str, Result]:
    """Run every task of ``tasks`` not yet in the result file ``out`` and return key ->
    result for all of them (module docstring). ``on_result`` is called after each new
    result is on disk (a test stops a campaign from there). ``progress``: a tqdm bar on
    stderr (default: when stderr is a terminal)."""
    if workers < 1:
        raise CampaignError(f"--workers: must be at least 1, got {workers}")
    done = read_results(out)
    keys = [t.key(seed) for t in tasks]
    todo = [(t, k) for t, k in zip(tasks, keys, strict=True) if k not in done]
    if todo:
        _run_on_ray(todo, seed, out, done, workers, address, desc, progress, on_result)
    return {k: done[k] for k in keys}


def _run_on_ray(todo: list[tuple[Task, str]], seed: int, out: Path, done: dict[str, Result],
                workers: int, address: str | None, desc: str, progress: bool | None,
                on_result: Callable[[Task, Result], None] | None) -> None:
    from tqdm import tqdm
    session = RaySession(workers, address)
    session.open()
    import ray
    remote = ray.remote(num_cpus=1)(execute)
    bar = tqdm(total=sum(t.count for t, _ in todo), desc=desc, unit="trial", leave=False,
               disable=not sys.stderr.isatty() if progress is None else not progress)
    pending: dict[Any, tuple[Task, str]] = {}
    queue = list(todo)

    def submit() -> None:
        while queue and len(pending) < workers:
            t, k = queue.pop(0)
            pending[remote.remote(t.kind, t.params, t.first, t.count, seed, t.group())] = (t, k)

    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        with open(out, "a") as f:
            submit()
            while pending:
                ready, _ = ray.wait(list(pending), num_returns=1)
                t, k = pending.pop(ready[0])
                submit()        # the freed worker gets its next task before the bookkeeping
                result = ray.get(ready[0])
                f.write(json.dumps({"key": k, "task": t.as_json(), "result": result}) + "\n")
                f.flush()
                os.fsync(f.fileno())
                done[k] = result
                bar.update(t.count)
                if on_result is not None:
                    on_result(t, result)
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)
        bar.close()
        session.close()
