"""A demo's parameters as one small dataclass: its fields make the command line and --help.

Each field says its default, its meaning, its unit and its range, once::

    @dataclass
    class Vessel(Parameters):
        \"\"\"Thick sphere or cylinder under internal pressure in J2 plasticity.\"\"\"

        shape: str = choice("sphere", ["sphere", "cylinder"], "hollow sphere or long cylinder")
        inner_radius: float = number(100.0, "a", unit="length", above=0)
        steps: int = number(10, "equal load steps", at_least=1)
        unload: bool = switch("unload to zero afterwards")

        def check(self):  # what involves several fields; a ValueError is one line, status 2
            if not self.inner_radius < self.outer_radius: raise ValueError("...")

`cli.arguments(Vessel, prefixes)` parses the command line (in a notebook: the flags in the
environment variable FENICS_NL_ARGS, else the defaults) and returns a `Vessel`. `OUTPUTS`
and `CHECKPOINTS` add the scene contract's output flags (--json always; --png, --plot,
--output, --checkpoint where a demo has them).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from collections.abc import Sequence
from typing import ClassVar

from fenics_nl.io import flags
from fenics_nl.vocabulary import OLD_NAMES, say_renamed

__all__ = ["Parameters", "choice", "number", "parser_of", "switch", "text"]


def number(default, meaning: str, *, unit: str | None = None, above: float | None = None,
           at_least: float | None = None, at_most: float | None = None,
           group: str | None = None, metavar: str | None = None):
    """A number flag: finite, within the bounds given; an integer if `default` is one.

    Bounds: > `above`, >= `at_least`, <= `at_most`. `default` None: optional (the demo
    decides what its absence means, said in `meaning`).
    `group`: flags of one group exclude each other (e.g. force or displacement control).
    """
    return dataclasses.field(default=default, metadata={
        "kind": "number", "meaning": meaning, "unit": unit, "above": above,
        "at_least": at_least, "at_most": at_most, "group": group, "metavar": metavar})


def choice(default: str, options: Sequence[str], meaning: str, *, spelling: bool = False):
    """One word among `options` (`spelling`: old spellings read, see `vocabulary`)."""
    return dataclasses.field(default=default, metadata={
        "kind": "choice", "meaning": meaning, "options": list(options), "spelling": spelling})


def switch(meaning: str, *, group: str | None = None):
    """An on/off flag, off by default."""
    return dataclasses.field(default=False, metadata={"kind": "switch", "meaning": meaning,
                                                      "group": group})


def text(default: str | None, meaning: str, *, metavar: str = "PATH"):
    """A word or a path, as given."""
    return dataclasses.field(default=default, metadata={"kind": "text", "meaning": meaning,
                                                        "metavar": metavar})


@dataclasses.dataclass
class Parameters:
    """Base of a demo's parameters; subclasses add their fields and `check`."""

    EPILOG: ClassVar[str | None] = None  # after the flags in --help (the PETSc prefixes)
    # the output flags: {"png": what it draws, "plot": ..., "output": the fields written}
    OUTPUTS: ClassVar[dict[str, str]] = {}
    JSON: ClassVar[str] = "the quantities of interest"
    CHECKPOINTS: ClassVar[bool] = False

    def check(self) -> None:
        """Conditions on several fields: raise ValueError (one line, status 2)."""

    def material_flags(self, *, power_law: dict, j2: dict | None = None) -> None:
        """Fill the chosen `material`'s flags with their defaults (in `check`).

        Power law: --sigma0, --n; j2: --sigma0, --hardening. A flag that sets only another
        material is a ValueError (one line, status 2).
        """
        own = {"power-law": power_law, "j2": j2 or {}}.get(self.material, {})
        others = sorted({k for d in (power_law, j2 or {}) for k in d} - set(own))
        given = [f"--{k}" for k in others if getattr(self, k, None) is not None]
        if given:
            owners = [m for m, d in (("the power law", power_law), ("j2", j2 or {}))
                      if any(g[2:] in d for g in given)]
            raise ValueError(f"{', '.join(given)} set {' and '.join(owners)}, not --material "
                             f"{self.material}")
        for k, v in own.items():
            if getattr(self, k) is None:
                setattr(self, k, v)
        if self.material == "j2" and self.hardening < 0:
            raise ValueError(f"--hardening must be >= 0, got {self.hardening:g}")


def _declared_integer(f: dataclasses.Field) -> bool:
    """Whether the field is declared `int` (or `int | None`: a default of None says nothing)."""
    declared = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", str(f.type))
    return declared.replace(" ", "").split("|")[0] == "int" or (
        isinstance(f.default, int) and not isinstance(f.default, bool))


def _number_type(f: dataclasses.Field):
    m, integer = f.metadata, _declared_integer(f)

    def parse(word: str):
        try:
            value = int(word) if integer else float(word)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"not {'an integer' if integer else 'a number'}: {word!r}") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"must be a finite number, got {word!r}")
        if m["above"] is not None and not value > m["above"]:
            raise argparse.ArgumentTypeError(f"must be > {m['above']:g}, got {word}")
        if m["at_least"] is not None and not value >= m["at_least"]:
            raise argparse.ArgumentTypeError(f"must be >= {m['at_least']:g}, got {word}")
        if m["at_most"] is not None and not value <= m["at_most"]:
            raise argparse.ArgumentTypeError(f"must be <= {m['at_most']:g}, got {word}")
        return value

    parse.__name__ = "integer" if integer else "number"
    return parse


class _OldName(argparse.Action):
    """A flag's old name: its value is the new flag's, and the note says so."""

    def __call__(self, parser, namespace, values, option_string=None):
        say_renamed(option_string, "--" + self.dest.replace("_", "-"))
        setattr(namespace, self.dest, values)


def _add(target, f: dataclasses.Field) -> None:
    """The flag of field `f` on the parser (or exclusive group) `target`, and its old names.

    An old name (`vocabulary.OLD_NAMES`) is read, said, and hidden from --help.
    """
    m = f.metadata
    flag = "--" + f.name.replace("_", "-")
    meaning = m["meaning"] + (f" [{m['unit']}]" if m.get("unit") else "")
    old = ["--" + k.replace("_", "-") for k, new in OLD_NAMES.items() if new == f.name]
    if m["kind"] == "number":
        kind = dict(type=_number_type(f), metavar=m["metavar"])
    elif m["kind"] == "choice":
        kind = dict(choices=m["options"], type=flags.spelling(flag) if m["spelling"] else None)
    elif m["kind"] == "switch":
        target.add_argument(flag, dest=f.name, action="store_true", help=meaning)
        return
    else:
        kind = dict(metavar=m["metavar"])
    target.add_argument(flag, dest=f.name, default=f.default, help=meaning, **kind)
    for name in old:
        target.add_argument(name, dest=f.name, default=argparse.SUPPRESS, action=_OldName,
                            help=argparse.SUPPRESS, **kind)


def parser_of(cls: type[Parameters]) -> argparse.ArgumentParser:
    """The command line of `cls`: its description, a flag a field, the output flags."""
    description = " ".join((cls.__doc__ or "").split("\n\n")[0].split())
    p = flags.parser(description, epilog=cls.EPILOG)
    groups: dict[str, argparse._MutuallyExclusiveGroup] = {}
    for f in dataclasses.fields(cls):
        if "kind" not in f.metadata:
            continue  # the output flags, added below
        group = f.metadata.get("group")
        if group and group not in groups:
            groups[group] = p.add_mutually_exclusive_group()
        _add(groups[group] if group else p, f)
    flags.add_outputs(p, json=cls.JSON, **cls.OUTPUTS)
    if cls.CHECKPOINTS:
        flags.add_checkpoints(p)
    return p


def from_namespace(cls: type[Parameters], p: argparse.ArgumentParser,
                   args: argparse.Namespace) -> Parameters:
    """The parameters parsed into `args`, checked (a failed check: `p.error`, status 2)."""
    values = cls(**{f.name: getattr(args, f.name) for f in dataclasses.fields(cls)
                    if hasattr(args, f.name)})
    for name, value in vars(args).items():  # the output flags: attributes of the instance
        if not hasattr(values, name):
            setattr(values, name, value)
    try:
        values.check()
    except ValueError as err:
        p.error(str(err))
    return values
