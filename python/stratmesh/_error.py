"""stratmesh.Error, raised for every refusal, and ArgumentTypeError, its kind for wrong types."""


class Error(ValueError):
    """A status from the library, or a refusal of the arguments before it is called.

    status: the status's name, as in the header's STRATMESH_STATUS_LIST ("invalid_point").
    message: the status's one-line explanation (stratmesh.STATUSES[status]).
    detail: the sentence on why (Report::detail, or the argument refused and why), or None.
    report: the report of the failed call, or None when it failed before the library ran.
    """

    def __init__(self, status, message, detail=None, report=None):
        super().__init__(f"{status}: {detail or message}")
        self.status = status
        self.message = message
        self.detail = detail
        self.report = report

    def __reduce__(self):
        # Rebuilt from all its fields when pickled, as a Dask worker's error reaching the client.
        return type(self), (self.status, self.message, self.detail, self.report)


class ArgumentTypeError(Error, TypeError):
    """An argument of the wrong type (a string where a number is expected, say), refused
    before the library runs: a stratmesh.Error that is also a TypeError."""
