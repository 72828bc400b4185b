"""Errors that name where bad input came from, so a user can fix the file, not guess."""

from __future__ import annotations


class InputError(ValueError):
    """Bad input: a config key, a data table cell, a measurement file.

    The message always names the file, and where known the row and field (column or key)
    and the offending value.
    """

    def __init__(self, file, problem, *, row=None, field=None, value=None):
        if hasattr(value, "item"):  # numpy scalars print as np.float64(...): show the plain number
            value = value.item()
        if hasattr(row, "item"):
            row = row.item()
        self.file, self.problem, self.row, self.field, self.value = str(file), problem, row, field, value
        where = [f"{self.file}"]
        if row is not None:
            where.append(f"row {row}")
        if field is not None:
            where.append(f"field '{field}'")
        if value is not None:
            where.append(f"value {value!r}")
        super().__init__(f"{', '.join(where)}: {problem}")


class ConfigError(InputError):
    """A configuration file that does not match the schema."""


class SolveFailed(RuntimeError):
    """A solve a result needs did not converge: the message says which and why, and no number
    is written for it (the command line reports it without a traceback)."""
