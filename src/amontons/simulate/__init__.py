"""Simulate the measured contact: scenes, load series, rendering like the microscope,
registration and comparison (docs/simulate.md)."""
