"""``tools/mutate.py --ray``: candidate mutants as Ray tasks (``campaign.runner``'s Ray:
a local Ray with ``--workers`` CPUs started on demand, or ``--ray-address`` / RAY_ADDRESS).

Each task is one mutant through ``tools.mutate.run_mutant`` (its own copy of the tree, so
tasks are independent); at most ``workers`` run at once, and verdicts come back as they
finish, for ``tools/mutate.py`` to print and save (``--resume`` skips the saved ones).
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from dataclasses import asdict
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from campaign.runner import RaySession  # noqa: E402 - after the repository is on sys.path


def _one(fields: dict[str, Any], timeout: float, quick: bool) -> tuple[str, float]:
    """One mutant (its fields: the class lives in tools/mutate_gen.py, which a worker
    imports through tools.mutate) on a Ray worker."""
    from tools.mutate import Mutant, run_mutant
    return run_mutant(Mutant(**fields), timeout, quick=quick)


def run_on_ray(mutants: list[Any], timeout: float, quick: bool, workers: int,
               address: str | None) -> Iterator[tuple[Any, str, float]]:
    """(mutant, verdict, seconds) of every mutant, in the order they finish."""
    import ray
    session = RaySession(workers, address)
    session.open()
    remote = ray.remote(num_cpus=1)(_one)
    queue = list(mutants)
    pending: dict[Any, Any] = {}
    try:
        while queue or pending:
            while queue and len(pending) < workers:
                m = queue.pop(0)
                pending[remote.remote(asdict(m), timeout, quick)] = m
            ready, _ = ray.wait(list(pending), num_returns=1)
            m = pending.pop(ready[0])
            verdict, secs = ray.get(ready[0])
            yield m, verdict, secs
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)
        session.close()
