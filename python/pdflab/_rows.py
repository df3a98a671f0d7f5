"""Rows of a table: what pdflab.sweep and pdflab.predict_weights return when
pandas is not installed (or frame=False), and how they become a DataFrame."""

import csv
import io
import math

# `pdflab sweep --csv`'s columns that are not plain numbers.
_TEXT = {"strategy"}
_FLAGS = {"unbiased", "best", "in_best_interval"}
_COUNTS = {"seeds", "spp"}


def _value(column, text):
    if column in _TEXT:
        return text
    if column in _FLAGS:
        return text == "1"
    if column in _COUNTS:
        return int(text) if text else None
    return float(text) if text else math.nan  # an empty field: no figure there; "inf" an unbounded interval


class Rows(list):
    """A list of dicts (one per row), with figures about the whole table in `attrs`, also readable as attributes
    (rows.summary, rows.best_weight)."""

    def __init__(self, rows=(), attrs=None):
        super().__init__(rows)
        self.attrs = dict(attrs or {})

    def __getattr__(self, name):
        attrs = self.__dict__.get("attrs", {})
        if name in attrs:
            return attrs[name]
        raise AttributeError(name)

    @property
    def columns(self):
        return list(self[0].keys()) if self else []

    def column(self, name):
        """One column as a list."""
        return [row[name] for row in self]

    def to_frame(self, pandas=None):
        """A pandas DataFrame of the rows, with the same attrs."""
        if pandas is None:
            import pandas
        frame = pandas.DataFrame(list(self), columns=self.columns or None)
        frame.attrs.update(self.attrs)
        return frame

    @staticmethod
    def parse_csv(text, summary=""):
        """The rows of a CSV that pdflab wrote, with its numbers as numbers."""
        reader = csv.DictReader(io.StringIO(text))
        rows = [{column: _value(column, value) for column, value in row.items()} for row in reader]
        return Rows(rows, {"summary": summary})
