"""Orbit stage: where the target, the observer and the Sun are, epoch by epoch."""
