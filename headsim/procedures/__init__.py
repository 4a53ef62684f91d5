"""The procedures a scenario can name, one module each, every one found on first lookup.

Each module holds a procedure's run (on the run's simulator, event hub and what
the head knows: :mod:`headsim.run.context`), its typed result, which writes its
results.json ``experiment`` fields, its summary lines and its recording rows, and
what its keys mean, gathered in a :class:`~headsim.procedures.contract.Procedure`
it registers.  :func:`headsim.procedures.contract.get` imports every module of
this package the first time it is asked, so a new module is found with no list
to edit.  The runner, results.json, the summary, the recording and the
references find a procedure by name and never name it.  CONTRIBUTING.md walks
through adding one.
"""
