"""The one registry of commands: every built-in command word, letter and
command statement of the language, with its handler, usage and help.

Three kinds of entries share :class:`Command`:

* words (``recalc``, ``bfgs``, ``quiet``), matched in lower case, and
  single letters (``g``, ``G``, ``V``), matched exactly, run as ``NAME`` or
  ``NAME expr`` by ``handler(interp, raw, arg)`` (``raw``: the word as
  typed; ``arg``: the argument's expression node or None);
* statements that the grammar parses itself (``list gen``, ``set ...``,
  ``refine gen``), keyed by their parse-tree tag and run by
  ``handler(interp, node)``;
* pyevolver's own commands (:mod:`pyevolver.commands.extensions`), which
  also take ``name("a", "b")``: ``call(session, args)`` with the evaluated
  arguments.

Families register their commands at import (:mod:`~pyevolver.commands.remesh`,
:mod:`~pyevolver.commands.evolution`, :mod:`~pyevolver.commands.toggles`,
:mod:`~pyevolver.commands.files`, ...); :mod:`pyevolver.commands.interpreter`
imports them all and only dispatches::

    from pyevolver.commands.registry import register

    @register("hello", usage="hello", help="print hello", family="demo")
    def _hello(interp, raw, arg):
        interp.session.write("hello\\n")
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

from ..errors import CommandError


@dataclass(frozen=True)
class Command:
    """A registered command.

    Attributes
    ----------
    names : tuple of str
        The words and letters that run it (the first is its name).
    handler : callable
        ``handler(interp, raw, arg)`` for words and letters,
        ``handler(interp, node)`` for statements.
    usage, help : str
        One line each, as ``help`` and the docs show them.
    family : str
        The module (``remesh``, ``toggles``, ...) that registered it.
    arg : str
        ``"optional"`` (the default) or ``"none"`` (``NAME expr`` is not
        this command: the word is then unknown).
    statement : str or None
        The parse-tree tag of a statement command (``list_``, ``set_``).
    call : callable or None
        ``call(session, args)`` of an extension (``name("a", ...)``).
    max_args : int
        Most arguments ``call`` takes.
    """

    names: tuple
    handler: Callable
    usage: str = ""
    help: str = ""
    family: str = ""
    arg: str = "optional"
    statement: Optional[str] = None
    call: Optional[Callable] = None
    max_args: int = 1
    extra: dict = field(default_factory=dict)

    @property
    def name(self) -> str:
        return self.names[0]


#: words (lower case) and single letters (exact case) -> Command
COMMANDS: dict[str, Command] = {}
#: parse-tree tag of a statement -> Command
STATEMENTS: dict[str, Command] = {}

_G_COUNT = re.compile(r"g\d+")


def _key(name: str) -> str:
    return name if len(name) == 1 else name.lower()


def register(*names: str, usage: str = "", help: str = "", family: str = "",
             arg: str = "optional", statement: Optional[str] = None,
             replace: bool = True, **extra: Any) -> Callable:
    """Decorator: register ``handler`` under ``names``.

    Parameters
    ----------
    *names : str
        Words (matched in lower case) and single letters (matched exactly).
    usage, help, family, arg, statement
        See :class:`Command`.
    replace : bool
        False: names already registered keep their command (the fallback
        tables of commands refused by name).
    """
    def deco(fn: Callable) -> Callable:
        cmd = Command(tuple(names), fn, usage, help, family, arg, statement, extra=extra)
        if statement is not None:
            STATEMENTS[statement] = cmd
            return fn
        for n in names:
            k = _key(n)
            if k in COMMANDS and not replace:
                continue
            if k in COMMANDS and COMMANDS[k].family != family:
                raise ValueError(f"command '{n}' registered twice ({COMMANDS[k].family}, "
                                 f"{family})")
            COMMANDS[k] = cmd
        return fn
    return deco


def add(cmd: Command) -> None:
    """Register a ready :class:`Command` under its names (extensions)."""
    for n in cmd.names:
        COMMANDS[_key(n)] = cmd


def lookup(raw: str, arg: Any = None) -> Optional[Command]:
    """The command the bare word or letter ``raw`` (with argument node
    ``arg``) runs, or None when it is not a built-in command."""
    if len(raw) == 1:
        cmd = COMMANDS.get(raw)
    else:
        cmd = COMMANDS.get(raw.lower())
        if cmd is None and _G_COUNT.fullmatch(raw):
            cmd = COMMANDS.get("g")
    if cmd is not None and cmd.arg == "none" and arg is not None:
        return None
    return cmd


def statement(kind: str) -> Command:
    """The statement command of parse-tree tag ``kind``."""
    return STATEMENTS[kind]


def words() -> set:
    """Every registered word and letter, statements' keywords included."""
    out = set(COMMANDS)
    for cmd in STATEMENTS.values():
        out.update(_key(n) for n in cmd.names)
    return out


def call(session: Any, name: str, args: list) -> None:
    """Run the extension ``name`` with evaluated ``args`` (``name(...)``)."""
    cmd = COMMANDS[name.lower()]
    if len(args) > cmd.max_args:
        raise CommandError(f"{name} takes at most {cmd.max_args} argument"
                           f"{'s' if cmd.max_args != 1 else ''} (usage: {cmd.usage})")
    if cmd.call is None:
        raise CommandError(f"{name} is not called with arguments in parentheses")
    cmd.call(session, args)
