"""stratmesh.Error: a library status other than ok, raised as a ValueError."""


class Error(ValueError):
    """A status from the library, or a refusal of the arguments before it is called.

    status: the status's name, as in the header's STRATMESH_STATUS_LIST ("invalid_point").
    detail: the library's sentence on why (Report::detail), or None.
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
