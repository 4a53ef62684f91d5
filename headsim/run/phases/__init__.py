"""The phases of a scenario run, one module each: the calibration and each procedure's
measurement; :mod:`headsim.run.runner` chooses and sequences them."""
