"""One scenario run: the runner, its progress, results files, the report and the Rerun recording."""
