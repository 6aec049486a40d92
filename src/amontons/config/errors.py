"""The one error a bad configuration or sample sheet raises (docs: config/README.md)."""


class ConfigError(ValueError):
    """A configuration or sample-sheet value is not what the workflow expects."""
