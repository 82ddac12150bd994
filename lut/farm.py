"""Batch baking on a Dask cluster: each paint type baked once, cluster-wide,
into one shared store.

The plan (``run``) has three phases, each a set of Dask tasks:

1. **Scan**, one task per .blend file: a fresh Blender child process opens
   the file and lists the paint types its used materials need
   (``addon.batch`` with ``--scan``): the paint, and the Blender's Metallic
   lobe and EEVEE calibration its fits are made for.
2. **Bake**, one task per distinct type (its LUT key, lobe and calibration):
   ``lut.render.bake.bake_for_render`` into the store, in the worker itself
   (numpy work, no Blender).  Writes are atomic (``lut.lutfiles.files``), so
   a worker killed mid-bake leaves no partial file under a final name, and
   the task runs again on another worker (Dask reschedules the tasks of a
   lost worker; an exception is retried ``retries`` times).  Two processes
   baking one type at once each write a complete file and the last rename
   stands: one valid file either way.
3. **Wire**, one task per file, started as soon as its types are baked: a
   fresh Blender child process bakes the file against the store (finding
   every type cached), wires its materials and saves it, as a local batch
   run does (``addon.batch`` with ``--store``).

Blender's data is one file per process, so Blender work never runs in the
worker itself: the tasks are handed the command that starts a child (the
client's: every node has Blender, or the project's Python with ``bpy``, at
the same path).  This module never imports ``bpy``; it needs ``distributed``
(the ``farm`` extra) only when a plan runs.

The report is a local run's (one entry per file), each file entry with
``types``: per paint type it renders, where and how long it was baked
(``worker``, ``seconds``, ``computed``: what the bake computed, empty when
it found the type baked)."""

from __future__ import annotations

import json
import os
import pathlib
import shutil
import socket
import subprocess
import sys
import tempfile
import time

#: How often a type's bake is retried after an exception of its own (a
#: worker that dies is handled by the scheduler: its tasks run elsewhere).
RETRIES = 2


class FarmUnavailable(RuntimeError):
    """The Dask distributed package is not installed."""


def validate_scheduler(scheduler: str) -> str:
    """``local:N`` (a cluster of N worker processes on this machine, N >= 1)
    or a scheduler's address (``tcp://host:port``, ``tls://…``)."""
    if scheduler.startswith("local:"):
        count = scheduler.partition(":")[2]
        if not count.isdigit() or int(count) < 1:
            raise ValueError(f"scheduler must be local:N with N a whole number >= 1, got {scheduler!r}")
        return scheduler
    if "://" not in scheduler:
        raise ValueError(f"scheduler must be local:N or an address such as tcp://host:8786, got {scheduler!r}")
    return scheduler


def _distributed():
    try:
        import distributed
    except ImportError:
        raise FarmUnavailable(
            "--scheduler needs Dask distributed: pip install -r requirements-farm.txt (or the 'farm' extra)"
        ) from None
    return distributed


def client_for(scheduler: str):
    """A Dask client of ``scheduler`` (``validate_scheduler``): for
    ``local:N`` a scheduler and N single-threaded worker processes started
    here as a farm starts them (``dask scheduler``, ``dask worker``), not
    forked from this process (which may be Blender, or import ``bpy``:
    a worker must not), and stopped with the client (``close``)."""
    distributed = _distributed()
    scheduler = validate_scheduler(scheduler)
    if not scheduler.startswith("local:"):
        return distributed.Client(scheduler)
    count = int(scheduler.partition(":")[2])
    folder = pathlib.Path(tempfile.mkdtemp(prefix="paint_lut_cluster"))
    address = folder / "scheduler.json"
    env = dict(os.environ)
    # The workers import this package by the name the client knows it by.
    root = str(pathlib.Path(__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
    common = ["--scheduler-file", str(address), "--no-dashboard", "--host", "127.0.0.1"]
    log = open(folder / "cluster.log", "wb")  # noqa: SIM115 (closed in close)
    processes = [
        subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_scheduler", *common, "--port", "0"],
            env=env, stdout=log, stderr=subprocess.STDOUT,
        ),
    ]  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        while not address.exists():
            if processes[0].poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"the local Dask scheduler did not start (see {folder / 'cluster.log'})")
            time.sleep(0.1)
        processes.append(
            subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", *common,
                 "--nworkers", str(count), "--nthreads", "1"],
                env=env, stdout=log, stderr=subprocess.STDOUT,
            )
        )  # fmt: skip
        client = distributed.Client(scheduler_file=str(address), timeout=60)
        client.wait_for_workers(count, timeout=120)
    except BaseException:
        _stop(processes, log, folder)
        raise
    client._paint_lut_local = (processes, log, folder)  # stopped with the client (close)
    return client


def _stop(processes, log, folder):
    for process in reversed(processes):  # the workers first
        process.terminate()
    for process in reversed(processes):
        try:
            process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
    log.close()
    shutil.rmtree(folder, ignore_errors=True)


def close(client) -> None:
    """Close a client of ``client_for`` and stop its local cluster, if any."""
    local = getattr(client, "_paint_lut_local", None)
    client.close()
    if local is not None:
        _stop(*local)


# ----------------------------------------------------------------------------- tasks (run on workers)


def run_child(command: list, path: str, extra: list) -> dict:
    """Run one Blender child on one file and return its report entry (the
    child's ``--report``); a child that writes none fails the file with the
    last line it printed."""
    with tempfile.TemporaryDirectory(prefix="paint_lut_farm") as tmp:
        report = pathlib.Path(tmp) / "report.json"
        done = subprocess.run([*command, path, "--report", str(report), *extra], capture_output=True, text=True)
        if report.exists():
            return json.loads(report.read_text())[0]
    reason = (done.stderr.strip().splitlines() or [f"the Blender child exited with status {done.returncode}"])[-1]
    return {"file": str(pathlib.Path(path).resolve()), "status": "failed", "reason": reason, "materials": {}}


def bake_type(spec: dict, store: str, force: bool = False) -> dict:
    """Bake one paint type into the store (a task of phase 2): ``spec`` is a
    scanned type (``paint``, ``exact_metallic``, ``eevee_calibration``).
    Returns where and how long: {"worker", "seconds", "computed"}."""
    from .paint.core import Paint
    from .render import bake as render_bake

    start = time.perf_counter()
    calibration = spec.get("eevee_calibration")
    result = render_bake.bake_for_render(
        Paint.from_dict(spec["paint"]),
        store,
        exact_metallic=bool(spec["exact_metallic"]),
        eevee_calibration=tuple(calibration) if calibration else None,
        force=force,
    )
    return {
        "worker": f"{socket.gethostname()}:{os.getpid()}",
        "seconds": round(time.perf_counter() - start, 3),
        "computed": list(result.computed),
    }


def wire_file(command: list, path: str, extra: list, baked: list) -> dict:
    """Phase 3: the file baked against the store (its types' bakes,
    ``baked``, are done: Dask starts this task once they are)."""
    return run_child(command, path, extra)


# ----------------------------------------------------------------------------- the plan


def type_id(spec: dict) -> str:
    """A scanned type's identity: its LUT key, lobe kind and calibration
    (one set of files in the store)."""
    calibration = spec.get("eevee_calibration")
    cal = "".join(str(v) for v in calibration[:2]) if calibration else "-"
    return f"{spec['key']}:{'metallic' if spec['exact_metallic'] else 'ggx'}:{cal}"


def run(
    files,
    scheduler: str,
    *,
    child: list,
    store=None,
    force=False,
    pack=False,
    bake=bake_type,
) -> list:
    """Bake ``files`` on a Dask cluster (module docstring): returns the
    report, one entry per file in the order given.  ``child``: the command
    that starts a Blender child running ``addon.batch`` (its arguments
    follow); ``store``: where every type's LUT and fits go (None: each
    file's own ``//paint_lut``, types still baked once per folder);
    ``bake``: the phase 2 task (``bake_type``)."""
    files = [str(pathlib.Path(f).resolve()) for f in files]
    if store is not None:
        store = str(pathlib.Path(store).resolve())
        pathlib.Path(store).mkdir(parents=True, exist_ok=True)
    client = client_for(scheduler)
    try:
        store_args = ["--store", store] if store else []
        scans = client.gather(
            client.map(run_child, [child] * len(files), files, [["--scan", *store_args]] * len(files), pure=False)
        )
        bakes, where = {}, {}
        for path, scan in zip(files, scans, strict=True):
            if scan.get("status") == "failed":
                continue
            for spec in scan.get("paint_types", []):
                directory = spec["store"]
                key = (type_id(spec), directory)
                where.setdefault(path, []).append(key)
                if key not in bakes:
                    bakes[key] = client.submit(bake, spec, directory, force, retries=RETRIES, pure=False)
        extra = [*store_args, *(["--pack"] if pack else [])]
        wires = {}
        for path, scan in zip(files, scans, strict=True):
            if scan.get("status") == "failed":
                continue
            deps = [bakes[k] for k in where.get(path, [])]
            wires[path] = client.submit(wire_file, child, path, extra, deps, pure=False)
        done = {}
        for key, future in bakes.items():
            try:
                done[key] = future.result()
            except Exception as exc:  # the wire phase bakes (or fails) the type itself and says why
                done[key] = {"failed": f"{type(exc).__name__}: {exc}"}
        for path in wires:
            if any("failed" in done[k] for k in where.get(path, [])):
                # A failed bake fails the tasks that wait on it: wire the file
                # anyway, its child bakes the type itself or reports why not.
                wires[path] = client.submit(wire_file, child, path, extra, [], pure=False)
        entries = []
        for path, scan in zip(files, scans, strict=True):
            if path not in wires:
                entries.append(scan)
                continue
            try:
                entry = wires[path].result()
            except Exception as exc:
                entry = {"file": path, "status": "failed", "reason": f"{type(exc).__name__}: {exc}", "materials": {}}
            entry["types"] = {k[0].partition(":")[0]: done[k] for k in dict.fromkeys(where.get(path, []))}
            entries.append(entry)
        return entries
    finally:
        close(client)
