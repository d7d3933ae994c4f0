"""The Evolver command language: parsing (:mod:`.parser`, :mod:`.split`),
the interpreter (:mod:`.interpreter`), the one registry of commands
(:mod:`.registry`) and the command families registered in it
(:mod:`.remesh`, :mod:`.evolution`, :mod:`.elements`, :mod:`.element_attrs`,
:mod:`.attributes`, :mod:`.constraints`, :mod:`.files`, :mod:`.output`,
:mod:`.listing`, :mod:`.toggles`, :mod:`.variables`, :mod:`.extensions`,
:mod:`.refused`).  Commands take the session as an argument (duck-typed);
no module here imports :mod:`pyevolver.session`.
"""
