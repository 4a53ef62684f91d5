"""One scenario run: the runner and its phases, events, progress, typed results,
results.json, the summary and the Rerun recording.  ``headsim.run(...)``, the Python
entry point, is :func:`headsim.runs.library.run`."""
