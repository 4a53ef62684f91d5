"""Many runs: the insensitivity study, sweeps, the bench, the paper's reproduction, plots."""
