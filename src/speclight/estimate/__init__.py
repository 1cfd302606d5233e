"""Estimation: from measured (or simulated) light curves back to the target's surface.

Plain-array cores first (numpy in, numpy out; see ``docs/design.md``); the commands of the
command line are built on them.
"""
