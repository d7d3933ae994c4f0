"""One exception hierarchy for pyevolver.

Library code raises these; only the CLI/REPL turns them into messages and
exit codes.
"""


class PyEvolverError(Exception):
    """Base class of every pyevolver error."""


class DatafileError(PyEvolverError):
    """A datafile could not be read.

    The message has the form ``FILE:LINE:COL: what was expected``, followed by
    the offending source line when it is known.
    """

    def __init__(self, message, filename=None, line=None, column=None, excerpt=None):
        self.message = message
        self.filename = filename
        self.line = line
        self.column = column
        self.excerpt = excerpt
        super().__init__(self.format())

    def format(self):
        where = self.filename or "<datafile>"
        if self.line is not None:
            where += f":{self.line}"
            if self.column is not None:
                where += f":{self.column}"
        text = f"{where}: {self.message}"
        if self.excerpt:
            text += "\n    " + self.excerpt.rstrip("\n")
            if self.column is not None and self.column >= 1:
                text += "\n    " + " " * (self.column - 1) + "^"
        return text


class UnsupportedError(PyEvolverError):
    """An Evolver feature that pyevolver recognises but refuses by name."""

    def __init__(self, feature, detail=""):
        self.feature = feature
        msg = f"not supported in pyevolver: {feature}"
        if detail:
            msg += f" ({detail})"
        super().__init__(msg)


class CommandError(PyEvolverError):
    """A command could not be parsed or executed; the surface is unchanged."""


class ExpressionError(PyEvolverError):
    """An expression could not be evaluated (unknown name, bad argument)."""


class ConstraintError(PyEvolverError):
    """A constraint projection failed to converge."""


class ConvergenceWarning(UserWarning):
    """An iteration did not converge (e.g. volume restoration)."""
