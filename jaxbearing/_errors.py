"""Errors a user can fix: they name the parameter, its value and the valid range."""

from __future__ import annotations


class UserInputError(ValueError):
    """Base class of every error caused by user input (printed as one line by the CLI)."""


class ConfigError(UserInputError):
    """A configuration value is missing, unknown, of the wrong type, or out of range.

    `field` is the dotted configuration key (e.g. ``roller.end_radius_mm``).
    """

    def __init__(self, field: str, message: str):
        self.field = field
        super().__init__(f"{field}: {message}")
