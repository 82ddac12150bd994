"""Batch baking on a Dask cluster: each paint type baked once, cluster-wide,
into one shared store.

The plan (``run``) has three phases, each a set of Dask tasks:

1. **Scan**, one task per few .blend files (``FILES_PER_TASK``): a fresh
   Blender child process opens each file and lists the paint types its
   used materials need (``addon.batch`` with ``--scan``): the paint, and
   the Blender's Metallic lobe and EEVEE calibration its fits are made for.
2. **Bake**, one task per distinct type (its LUT key, lobe and calibration):
   ``lut.render.bake.bake_for_render`` into the store, in the worker itself
   (numpy work, no Blender).  Writes are atomic (``lut.lutfiles.files``), so
   a worker killed mid-bake leaves no partial file under a final name, and
   the task runs again on another worker (Dask reschedules the tasks of a
   lost worker; an exception is retried ``RETRIES`` times).  Two processes
   baking one type at once each write a complete file and the last rename
   stands: one valid file either way.
3. **Wire**, one task per scanned chunk of files, started as soon as their
   types are baked: a fresh Blender child process bakes the files against
   the store (finding every type cached), wires their materials and saves
   them, as a local batch run does (``addon.batch`` with ``--store``).  A
   child that crashes is run again on each of its files alone
   (``run_child``), so only the file that crashes Blender fails.

Blender's data is one file per process, so Blender work never runs in the
worker itself: the tasks are handed the command that starts a child (the
client's: every node has Blender, or the project's Python with ``bpy``, at
the same path).  This module never imports ``bpy``; it needs ``distributed``
(the ``farm`` extra) only when a plan runs.

The report is a local run's (one entry per file), each file entry with
``types``: per paint type it renders, where and how long it was baked
(``worker``, ``seconds``, ``computed``: what the bake computed, empty when
it found the type baked; ``store``: the folder)."""

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
    # Should this process die without stopping them (SIGKILL), the scheduler
    # stops once no client has used it for a while, and the workers once
    # their scheduler is gone.
    processes = [
        subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_scheduler", *common, "--port", "0",
             "--idle-timeout", LOCAL_IDLE_TIMEOUT],
            env=env, stdout=log, stderr=subprocess.STDOUT,
        ),
    ]  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        while not address.exists():
            if processes[0].poll() is not None or time.monotonic() > deadline:
                raise RuntimeError("the local Dask scheduler did not start: " + _tail(folder / "cluster.log"))
            time.sleep(0.1)
        processes.append(
            subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", *common,
                 "--nworkers", str(count), "--nthreads", "1", "--death-timeout", LOCAL_DEATH_TIMEOUT],
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


#: How long a local cluster outlives a client that died without stopping it.
LOCAL_IDLE_TIMEOUT = "120s"
LOCAL_DEATH_TIMEOUT = "60s"


def _tail(path, lines=5) -> str:
    try:
        return " | ".join(path.read_text(errors="replace").strip().splitlines()[-lines:]) or "no output"
    except OSError:
        return "no output"


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
    try:
        client.close()
    finally:
        if local is not None:
            _stop(*local)


# ----------------------------------------------------------------------------- tasks (run on workers)


def failed_entry(path, reason: str) -> dict:
    """The report entry of a file that failed as a whole (the batch's
    format: ``addon.batch.bake_file``), named by its resolved path."""
    return {"file": str(pathlib.Path(path).resolve()), "status": "failed", "reason": reason, "materials": {}}


def run_child(command: list, paths: list, extra: list) -> list:
    """Run one Blender child on some files and return their report entries,
    in the order of ``paths`` (the child's ``--report``).  A child that
    writes none (it crashed) is run again on each file alone, so the file
    that crashes it fails alone, with the child's exit status and the last
    line it printed."""
    with tempfile.TemporaryDirectory(prefix="paint_lut_farm") as tmp:
        report = pathlib.Path(tmp) / "report.json"
        done = subprocess.run([*command, *paths, "--report", str(report), *extra], capture_output=True, text=True)
        if report.exists():
            entries = json.loads(report.read_text())
            if len(entries) == len(paths):
                return entries
    if len(paths) > 1:
        return [entry for path in paths for entry in run_child(command, [path], extra)]
    last = (done.stderr.strip().splitlines() or ["no output"])[-1]
    reason = f"the Blender child exited with status {done.returncode} ({last})"
    return [failed_entry(paths[0], reason)]


def bake_type(spec: dict, store: str, force: bool = False) -> dict:
    """Bake one paint type into the store (a task of phase 2): ``spec`` is a
    scanned type (``paint``, ``exact_metallic``, ``eevee_calibration``,
    ``eevee_mode``).
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
        eevee_mode=spec.get("eevee_mode", render_bake.fitting.DEFAULT_EEVEE_MODE),
        force=force,
    )
    return {
        "worker": f"{socket.gethostname()}:{os.getpid()}",
        "seconds": round(time.perf_counter() - start, 3),
        "computed": list(result.computed),
    }


def wire_files(command: list, paths: list, extra: list, baked: list) -> list:
    """Phase 3: files baked against the store once their types' bakes
    (``baked``) are done (Dask starts this task then)."""
    return run_child(command, paths, extra)


# ----------------------------------------------------------------------------- the plan


def type_id(spec: dict) -> str:
    """A scanned type's identity: its LUT key, lobe kind, calibration and
    EEVEE mode (one set of files in the store)."""
    calibration = spec.get("eevee_calibration")
    cal = "".join(str(v) for v in calibration[:2]) if calibration else "-"
    return f"{spec['key']}:{'metallic' if spec['exact_metallic'] else 'ggx'}:{cal}:{spec.get('eevee_mode', '-')}"


#: Files per Blender child (a scan or wire task): a child's start (Blender
#: and the add-on) costs about as much as opening and saving a few files.
FILES_PER_TASK = 4


def run(
    files,
    scheduler: str,
    *,
    child: list,
    store=None,
    force=False,
    pack=False,
    files_per_task=FILES_PER_TASK,
    bake=bake_type,
) -> list:
    """Bake ``files`` on a Dask cluster (module docstring): returns the
    report, one entry per file in the order given.  ``child``: the command
    that starts a Blender child running ``addon.batch`` (its arguments
    follow); ``store``: where every type's LUT and fits go (None: each
    file's own ``//paint_lut``, types baked once per folder); ``force``:
    bake every type again (and wire every file anew); ``files_per_task``:
    files per Blender child; ``bake``: the phase 2 task (``bake_type``)."""
    distributed = _distributed()
    if int(files_per_task) < 1:
        raise ValueError(f"files_per_task must be a whole number >= 1, got {files_per_task!r}")
    given = [str(pathlib.Path(f).resolve()) for f in files]
    unique = list(dict.fromkeys(given))  # a file listed twice is baked and saved once
    chunks = [tuple(unique[i : i + int(files_per_task)]) for i in range(0, len(unique), int(files_per_task))]
    if store is not None:
        store = str(pathlib.Path(store).resolve())
        pathlib.Path(store).mkdir(parents=True, exist_ok=True)
    store_args = ["--store", store] if store else []
    # A forced run's types are baked again in phase 2; its files are wired
    # anew from those bakes, not baked a second time.
    extra = [*store_args, *(["--pack"] if pack else []), *(["--rewire"] if force else [])]
    client = client_for(scheduler)
    try:
        scans = {
            client.submit(run_child, child, list(chunk), ["--scan", *store_args], retries=1, pure=False): chunk
            for chunk in chunks
        }
        entries, bakes, where, wires = {}, {}, {}, {}
        # Each chunk's types are baked, and its files wired, as soon as it is scanned.
        for future in distributed.as_completed(scans):
            chunk = scans[future]
            try:
                scanned = dict(zip(chunk, future.result(), strict=True))
            except Exception as exc:  # e.g. no Blender at that path on the worker's node
                reason = f"cannot scan on the cluster: {type(exc).__name__}: {exc}"
                scanned = {p: failed_entry(p, reason) for p in chunk}
            entries.update(scanned)
            ready = [p for p, e in scanned.items() if e.get("status") != "failed"]
            keys = []
            for path in ready:
                for spec in scanned[path].get("paint_types", []):
                    key = (type_id(spec), spec["store"])
                    where.setdefault(path, []).append(key)
                    keys.append(key)
                    if key not in bakes:
                        bakes[key] = client.submit(bake, spec, spec["store"], force, retries=RETRIES, pure=False)
            if ready:
                deps = [bakes[k] for k in dict.fromkeys(keys)]
                wires[tuple(ready)] = client.submit(wire_files, child, ready, extra, deps, pure=False)
        done = {}
        for key, future in bakes.items():
            try:
                done[key] = {**future.result(), "store": key[1]}
            except Exception as exc:  # the wire phase bakes (or fails) the type itself and says why
                done[key] = {"failed": f"{type(exc).__name__}: {exc}", "store": key[1]}
        for paths in list(wires):
            if any("failed" in done[k] for p in paths for k in where.get(p, [])):
                # A failed bake fails the tasks that wait on it: wire the files
                # anyway, their child bakes the type itself or reports why not.
                wires[paths] = client.submit(wire_files, child, list(paths), extra, [], pure=False)
        for paths, future in wires.items():
            try:
                wired = future.result()
            except Exception as exc:
                reason = f"{type(exc).__name__}: {exc}"
                wired = [failed_entry(p, reason) for p in paths]
            for path, entry in zip(paths, wired, strict=True):
                entry["types"] = {k[0].partition(":")[0]: done[k] for k in dict.fromkeys(where.get(path, []))}
                entries[path] = entry
        return [entries[f] for f in given]
    finally:
        close(client)
