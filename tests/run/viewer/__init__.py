"""Helpers of the browser test: open a recording in headless Chromium and judge each view."""
