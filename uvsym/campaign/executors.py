"""Where a campaign's runs execute: local worker processes, or a Dask cluster.

An executor's ``run(chunks, settings, on_chunk)`` executes every run of ``chunks`` (lists of
:class:`~uvsym.campaign.spec.Run`) and calls ``on_chunk(index, rows)`` in the calling process as
each chunk completes (its rows in the chunk's order). ``start()`` connects, before any run, and
``close()`` releases the workers.

:class:`LocalExecutor` hands one chunk at a time to each of its processes (run there by
:func:`~uvsym.campaign.worker.execute_many`, in lanes where the runs share a loop); a process that
dies during a chunk is replaced and the chunk's runs are tried again one by one; a process that dies
during a run alone is replaced and the run tried again ``RETRIES`` times; then it gets an error row
(``WorkerDied``: a rerun of the campaign tries it again), and the other runs go on.
:class:`DaskExecutor` submits one task per chunk to the scheduler at ``scheduler`` (or to a
``LocalCluster`` it starts when none is given); a chunk whose task fails (a worker killed) is
resubmitted run by run, one after the other, and a run that fails alone gets an error row.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
from collections import deque
from multiprocessing.connection import wait

from uvsym.campaign import worker
from uvsym.errors import ExecutorError

__all__ = ["LocalExecutor", "DaskExecutor", "make_executor", "default_workers", "start_forkserver", "RETRIES"]

RETRIES = 2  # a run whose worker process dies is tried this many more times before its error row


def default_workers() -> int:
    """Local worker processes when none are asked for: the cores this process may use."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


# one thread per worker process for the numeric libraries, as Dask's nanny does: idle BLAS threads spin and
# take cores from the other workers' runs
_SINGLE_THREADED = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
# the forkserver starts as 'python -c', which would put the working folder first on its sys.path: a folder
# there named uvsym (the parent of a checkout) would be the uvsym its preload imports and every worker inherits.
# Without it (safe path) the forkserver finds the parent's uvsym; each worker then takes the parent's sys.path.
_SAFE_PATH = {"PYTHONSAFEPATH": "1"}
# glibc's malloc, read at each process's start: a worker allocates the same few-megabyte output tables run after
# run; from the heap (up to 32 MiB an allocation) and kept there when freed (up to 1 GiB), they come back without
# the page faults and zeroing of fresh pages (the docking campaign: 6.8 against 5.3 ms per 100 s run). Peak
# memory is the same; other C libraries ignore these.
_MALLOC = {"MALLOC_MMAP_THRESHOLD_": str(32 * 2 ** 20), "MALLOC_TRIM_THRESHOLD_": str(2 ** 30)}


@contextlib.contextmanager
def _worker_environment():
    """os.environ with _SINGLE_THREADED, _SAFE_PATH and _MALLOC where the user set none, for processes (and the
    forkserver) started inside."""
    added = {key: value for key, value in (_SINGLE_THREADED | _SAFE_PATH | _MALLOC).items() if key not in os.environ}
    os.environ.update(added)
    try:
        yield
    finally:
        for key in added:
            os.environ.pop(key, None)


def _context():
    """forkserver where there is one (workers fork from a clean process that imported uvsym once), else spawn."""
    if "forkserver" in multiprocessing.get_all_start_methods():
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(["uvsym.campaign.worker", "uvsym.sim.simulation"])
        return context
    return multiprocessing.get_context("spawn")


def start_forkserver() -> None:
    """Start the local workers' forkserver now, in the workers' environment, where the platform has one: its
    imports (CasADi, numpy, uvsym's simulator: about 0.4 s) then run beside the caller's own work (reading a
    campaign), and the first workers fork from a warm process. Idempotent; nothing where there is no forkserver."""
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return
    from multiprocessing import forkserver

    _context()
    with _worker_environment():
        forkserver.ensure_running()


class LocalExecutor:
    """``workers`` local processes (default: the cores)."""

    def __init__(self, workers: int | None = None):
        self.workers = workers or default_workers()
        self._processes: list = []

    def start(self) -> None:
        """Nothing to connect to: processes start with the runs."""

    def _spawn(self, settings):
        parent, child = self._context.Pipe()
        process = self._context.Process(target=worker.serve, args=(child, settings), daemon=True)
        with _worker_environment():
            process.start()
        child.close()
        self._processes.append((process, parent))
        return process, parent

    def run(self, chunks, settings, on_chunk) -> None:
        self._context = _context()
        pending = deque((index, list(chunk)) for index, chunk in enumerate(chunks) if chunk)  # jobs: runs of a chunk
        left = {index: len(chunk) for index, chunk in enumerate(chunks)}
        rows: dict[int, dict] = {index: {} for index in left}
        idle = [self._spawn(settings) for _ in range(min(self.workers, len(pending)))]
        busy: dict = {}  # (process, conn) -> (chunk index, runs)
        lost = [0]  # processes found dead while idle
        deaths: dict[str, int] = {}  # run id -> worker processes that died under it alone

        def dispatch() -> None:
            """A pending job to each idle process."""
            while idle and pending:
                slot, job = idle.pop(), pending.popleft()
                try:
                    slot[1].send(job[1])
                except OSError:  # the idle process has gone: replace it, the job waits for the next
                    lost[0] += 1
                    if lost[0] > 2 * self.workers:
                        raise ExecutorError(f"{lost[0]} local worker processes ended before taking a run "
                                            f"(last exit code {slot[0].exitcode})") from None
                    pending.appendleft(job)
                    self._processes.remove(slot)
                    idle.append(self._spawn(settings))
                    continue
                busy[slot] = job

        try:
            while pending or busy:
                dispatch()
                ready = set(wait([s[1] for s in busy] + [s[0].sentinel for s in busy]))
                for slot in [s for s in busy if s[1] in ready or s[0].sentinel in ready]:
                    (process, conn), (index, runs) = slot, busy.pop(slot)
                    answer = None
                    try:
                        if conn.poll():
                            answer = conn.recv()
                    except (EOFError, OSError):
                        pass
                    if answer is None:  # the process died during the job: replaced, its runs tried again
                        process.join(5.0)
                        conn.close()
                        self._processes.remove(slot)
                        answer = self._after_death(index, runs, deaths, pending, process.exitcode)
                        if pending:
                            idle.append(self._spawn(settings))
                        if answer is None:
                            continue
                    else:
                        idle.append(slot)
                        dispatch()  # its next job before this one's rows are written: the process never waits on them
                    for run, row in zip(runs, answer):
                        rows[index][run.id] = row
                    left[index] -= len(runs)
                    if not left[index]:
                        on_chunk(index, [rows[index][r.id] for r in chunks[index]])
                        del rows[index]
        finally:
            self.close()

    @staticmethod
    def _after_death(index: int, runs: list, deaths: dict, pending: deque, exitcode) -> list[dict] | None:
        """A job whose process died: several runs go back one by one (to find the one at fault); a run
        alone is tried again up to RETRIES times, then answered with its error row (returned)."""
        if len(runs) > 1:
            pending.extendleft((index, [run]) for run in reversed(runs))
            return None
        run = runs[0]
        deaths[run.id] = deaths.get(run.id, 0) + 1
        if deaths[run.id] <= RETRIES:
            pending.appendleft((index, [run]))
            return None
        return [worker.failure_row(run, f"WorkerDied: the worker process ended (exit code {exitcode}) during "
                                        f"this run, {deaths[run.id]} times")]

    def close(self) -> None:
        for _, conn in self._processes:
            try:
                conn.send(None)
            except OSError:
                pass
        for process, conn in self._processes:
            process.join(2.0)
            if process.is_alive():
                process.terminate()
                process.join(2.0)
            conn.close()
        self._processes = []


def _distributed():
    try:
        import distributed
    except ImportError:
        raise ExecutorError("the Dask executor needs dask.distributed: pip install 'uvsym[cluster]'") from None
    return distributed


class DaskExecutor:
    """Chunks as tasks on the Dask scheduler at ``scheduler`` ('tcp://host:8786'), reached within
    ``timeout_s`` s; without a scheduler, a LocalCluster of ``workers`` single-threaded processes."""

    def __init__(self, scheduler: str | None = None, workers: int | None = None, timeout_s: float = 10.0):
        self.scheduler, self.workers, self.timeout_s = scheduler, workers, timeout_s
        self.client = self.cluster = None

    def start(self) -> None:
        """Connect (or start the LocalCluster); ExecutorError naming the address when it cannot be reached."""
        distributed = _distributed()
        if self.scheduler is None:
            self.cluster = distributed.LocalCluster(n_workers=self.workers or default_workers(),
                                                    threads_per_worker=1, processes=True, dashboard_address=None)
            address = self.cluster.scheduler_address
        else:
            address = self.scheduler
        try:
            self.client = distributed.Client(address, timeout=self.timeout_s)
        except (OSError, TimeoutError, ValueError) as exc:
            self.close()
            raise ExecutorError(f"cannot reach the Dask scheduler at {address} within {self.timeout_s:g} s: "
                                f"{exc}") from None

    def run(self, chunks, settings, on_chunk) -> None:
        distributed = _distributed()
        if self.client is None:
            self.start()
        futures = {self.client.submit(worker.run_chunk, chunk, settings, pure=False): (index, None)
                   for index, chunk in enumerate(chunks)}
        rows_by_run: dict[int, dict] = {}  # chunk rerun run by run -> the rows so far
        queue = distributed.as_completed(list(futures))

        def submit_next(index: int) -> None:
            """The next run of failed chunk ``index`` alone, after the one before it has ended: a run that kills
            its worker then takes no other run of the chunk with it."""
            run = chunks[index][len(rows_by_run[index])]
            single = self.client.submit(worker.run_chunk, [run], settings, pure=False)
            futures[single] = (index, run)
            queue.add(single)

        for future in queue:
            index, alone = futures.pop(future)
            chunk = chunks[index]
            try:
                rows = future.result()
            except Exception as exc:  # a worker died under the task, or the task could not run
                if alone is None and len(chunk) > 1:  # find the run at fault
                    rows_by_run[index] = {}
                    submit_next(index)
                    continue
                rows = [worker.failure_row(alone or chunk[0], f"{type(exc).__name__}: {exc}")]
            if alone is None:
                on_chunk(index, rows)
                continue
            rows_by_run[index][alone.id] = rows[0]
            if len(rows_by_run[index]) < len(chunk):
                submit_next(index)
            else:
                by_run = rows_by_run.pop(index)
                on_chunk(index, [by_run[run.id] for run in chunk])

    def close(self) -> None:
        for resource in (self.client, self.cluster):
            if resource is not None:
                resource.close()
        self.client = self.cluster = None


def make_executor(kind: str = "local", *, workers: int | None = None, scheduler: str | None = None,
                  timeout_s: float = 10.0):
    """The executor ``kind`` ("local" or "dask"; a scheduler address implies dask)."""
    if scheduler is not None or kind == "dask":
        return DaskExecutor(scheduler, workers, timeout_s)
    if kind != "local":
        raise ExecutorError(f"executor: unknown kind {kind!r}; known: local, dask")
    return LocalExecutor(workers)
