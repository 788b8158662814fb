"""Identification over many logs on a Dask cluster (issue 31; docs/fleet.md).

The per-file step is ``dynid.stream_partial``: a CSV run read in constant memory into its
least-squares state (the bytes of the .dpart format, tens of kB). The states of disjoint runs add
up exactly, so the fleet fit is a map of that step over the files and a tree reduction with
``dynid.merge_partials``; the last state is solved here with ``dynid.solve_partial``. Only the
states cross the network, never the samples: each worker reads its files itself, so the paths must
be valid on the workers (a shared file system or object store mount).
"""
from . import _core

__all__ = ["identify", "partial_of_files", "compare"]

compare = _core.compare


def partial_of_files(files, robot, joints=(), lock=None, **options):
    """The state of ``files`` (a list of CSV paths) as bytes: what one task of the map returns.
    Loads ``robot`` (built-in name or a path valid on this worker) with ``joints``/``lock`` as
    ``dynid.load_model`` does; ``options`` as ``dynid.stream_partial``."""
    model = _core.load_model(robot, list(joints), dict(lock or {}))
    return _core.stream_partial(model, list(files), robot=robot, **options)


def _merge(parts):
    return _core.merge_partials(list(parts))


def identify(files, robot, client=None, *, joints=(), lock=None, split_every=8,
             progress=False, return_partial=False, **options):
    """Identifies one model from many runs on a Dask cluster, as ``dynid merge`` of the parts of
    ``identify --stream --partial`` over the same files gives it.

    files: CSV runs (q*, dq*, ddq*, tau*; no filtering: see ``dynid identify --stream``), one task
    each. robot: built-in name or model path, loaded on each worker. client: a
    ``dask.distributed.Client`` (e.g. ``Client("tcp://scheduler:8786")``); default: a
    ``LocalCluster`` of 2 single-threaded worker processes, closed on return. split_every: parts
    merged per reduction task. progress: show the engine's own progress bar
    (``dask.distributed.progress``) while the parts are made. options: as
    ``dynid.stream_partial`` (armature, viscous, coulomb, offset, asymmetric, estimator,
    confidence, zero_velocity, householder, threads). Returns the result dict (keys of the
    result JSON), or with return_partial=True the tuple (result, merged part bytes).
    Raises dynid.Error for a file the stream cannot read, parts that do not merge, and
    ValueError for an empty list of files or split_every < 2."""
    files = [str(f) for f in files]
    if not files:
        raise ValueError("files is empty: give at least one run")
    if split_every < 2:
        raise ValueError("split_every must be at least 2")
    from dask.distributed import Client, LocalCluster

    own = None
    if client is None:
        own = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=None)
        client = Client(own)
    try:
        futures = client.map(partial_of_files, [[f] for f in files], robot=robot,
                             joints=tuple(joints), lock=dict(lock or {}), pure=False,
                             **options)
        if progress:
            from dask.distributed import progress as engine_progress
            engine_progress(futures)
        level = list(futures)
        while len(level) > 1:
            level = [client.submit(_merge, level[i:i + split_every], pure=False)
                     for i in range(0, len(level), split_every)]
        merged = level[0].result()
    finally:
        if own is not None:
            client.close()
            own.close()
    result = _core.solve_partial(merged)
    return (result, merged) if return_partial else result
