"""Many runs at once on dask.distributed: a LocalCluster on one machine, or a scheduler's
cluster with the same code (every worker must see femb and the scenes' files at the same paths).

    import femb
    from dask.distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
        outcomes = femb.sweep(jobs, client=client)

A run that fails returns its error (femb.InputError, femb.NumericalError with the results up to
the failure, or any exception the job raised) in its place; the others go on.
"""

import functools


def _run_one(job, threads):
    try:
        if hasattr(job, "run"):
            return job.run(threads=threads)
        return job()
    except Exception as error:  # returned in the job's place: one bad job does not stop the sweep
        return error


def sweep(jobs, client=None, threads=1):
    """Runs each job and returns their outcomes in order: a job is a femb.Scene (run in memory,
    its Results returned) or a callable without arguments (its return value, e.g. a peak picked
    from the results, so that only that travels back). client: a dask.distributed Client; None:
    one after another in this process. threads: each run's threads (1 suits one worker per core).
    """
    jobs = list(jobs)
    run = functools.partial(_run_one, threads=threads)
    if client is None:
        return [run(job) for job in jobs]
    futures = client.map(run, jobs, pure=False)
    return client.gather(futures)
