"""What every ``lenslab`` command shares: exit statuses, one-line errors, argparse that reports a usage error in
one line, and the arguments made from the options table (scene/options.py). ``lenslab``, ``lenslab batch`` and
``lenslab validate`` import this module; none of them imports another's."""

from __future__ import annotations

import argparse

from lenslab.scene.options import OPTIONS, Option, format_bound

EXIT_OK, EXIT_ERROR, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130


class CliError(Exception):
    """A failure to report as one line, with an exit status."""

    def __init__(self, message: str, status: int = EXIT_ERROR):
        super().__init__(message)
        self.status = status


class CommandParser(argparse.ArgumentParser):
    """argparse for every ``lenslab`` command: a usage error is a CliError of one line, not a usage block."""

    def error(self, message: str):
        raise CliError(f"{message} (see {self.prog} --help)", EXIT_USAGE)

    def parse_known_args(self, args=None, namespace=None):
        return super().parse_known_args(self._negative_values_attached(args), namespace)

    def _negative_values_attached(self, args):
        """``--shutter -1/60`` as ``--shutter=-1/60``: argparse takes a value that starts with '-' for a value only
        when it reads as a plain negative number (-2, -0.5), so a negative fraction or a negative "-1e3" would be
        "expected one argument". Attached to its flag, it reaches the option's own check, which says what is
        wrong with it."""
        import sys

        args = list(sys.argv[1:] if args is None else args)
        takes_value = {flag for action in self._actions if action.option_strings and action.nargs is None
                       and action.const is None for flag in action.option_strings if flag.startswith("--")}
        joined, i = [], 0
        while i < len(args):
            arg = args[i]
            if (arg in takes_value and i + 1 < len(args) and len(args[i + 1]) > 1
                    and args[i + 1][0] == "-" and (args[i + 1][1].isdigit() or args[i + 1][1] == ".")):
                joined.append(f"{arg}={args[i + 1]}")
                i += 2
                continue
            joined.append(arg)
            i += 1
        return joined


def number_argument(kind, low: float, high: float):
    """An argparse type: an int or float in [low, high], refused in one line naming the value."""
    def parse(text: str):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {'a whole number' if kind is int else 'a number'}, "
                                             f"not '{text}'") from None
        if not low <= value <= high or value != value:
            raise argparse.ArgumentTypeError(f"{text} is out of range [{format_bound(low)}, {format_bound(high)}]")
        return value

    return parse


def option_argument(option: Option):
    """An argparse type for an option of the table: the user's text checked as the option checks it (argparse
    names the flag, so the message does not). A preset file that cannot be read is an error of its own."""
    from lenslab.optics.presetfiles import PresetError

    def parse(text: str):
        try:
            return option.from_text(text)
        except PresetError as exc:
            raise CliError(str(exc)) from None
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc).removeprefix(option.name + " ")) from None

    parse.__name__ = option.name
    return parse


def add_option(parser, name: str, **changes) -> None:
    """The option ``name`` of the table as an argument of ``parser`` (or of an argument group): its flag and its
    older spellings, its help, its choices or its checked type; ``changes`` replace what argparse is given."""
    option = OPTIONS[name]
    flags = [option.flag, *option.old_flags]
    settings: dict = dict(dest=option.name, help=_help(option))
    if option.kind is bool:
        settings["action"] = argparse.BooleanOptionalAction
    elif option.allowed is not None:
        settings["choices"] = option.allowed
    else:
        settings.update(type=option_argument(option), metavar=option.metavar)
    settings.update(changes)
    parser.add_argument(*flags, **settings)


_UNIT_WORDS = {"mm": "millimetres", "m": "metres", "s": "seconds", "stops": "stops"}


def _help(option: Option) -> str:
    """The option's help, its unit named where the help does not already name it."""
    if not option.unit or _UNIT_WORDS.get(option.unit, option.unit) in option.help:
        return option.help
    return f"{option.help} ({_UNIT_WORDS.get(option.unit, option.unit)})"


def parse_defines(items: list[str]) -> dict[str, str]:
    """``-D NAME=VALUE`` arguments (Mitsuba XML parameters) as a dictionary."""
    defines = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise CliError(f"-D {item}: expected NAME=VALUE", EXIT_USAGE)
        defines[name.strip()] = value
    return defines
