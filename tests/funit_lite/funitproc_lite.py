#!/usr/bin/env python3
"""funit-lite: minimal preprocessor for pFUnit .pf test files (standard library only).

Used by cmake/EmpmFunitLite.cmake when pFUnit 4.x is not installed, so the same .pf
files build under real pFUnit and under funit-lite.  Two sub-commands:

  funitproc_lite.py process INPUT.pf OUTPUT.F90
      Turn one .pf file into plain Fortran (no cpp directives are emitted): the user's
      module with every directive expanded, followed by a registration module
      `wrap_<module>` that holds `<module>_suite(n_passed, n_failed)`.

  funitproc_lite.py driver --output DRIVER.f90 [--extra-use MOD]
                    [--extra-initialize SUB] [--extra-finalize SUB] MODULE...
      Write the main program that runs the suites of the given modules in order, prints
      `N passed, N failed` and ends with `error stop 1` when any test failed.

Supported .pf subset (anything else starting with `@` is an error):
  * exactly one `module <name>` per file; <name> must equal the file's base name (pFUnit's
    add_pfunit_ctest registers the suite `<basename>_suite`);
  * `@test` (no arguments), followed by `subroutine <name>()` (no dummy arguments);
  * `@before` / `@after`, followed by `subroutine <name>()`: run around every test;
  * `@assertEqual`, `@assertTrue`, `@assertFalse`, `@assertLessThan`,
    `@assertLessThanOrEqual`, `@assertGreaterThan`, `@assertGreaterThanOrEqual`,
    `@assertRelativelyEqual`, `@assertIsFinite`, each `@assertX(args)` alone on one
    line, expanded as pFUnit does to
    `call assertX(args, location=SourceLocation('file.pf', LINE))` followed by
    `if (anyExceptions()) return`, where LINE is the line of the `@`;
  * as pFUnit 4.x requires: no `&` continuation of a directive, directive lines of at most
    128 columns (pFUnit writes `call ` in place of `@`; the result must fit in 132 columns),
    nothing else on a directive line (no trailing comment) and no comment on the `module`
    line;
  * the module must `use funit`.

Errors are reported on stderr as `file.pf:LINE: message` (exit status 1), e.g.
`file.pf:12: unsupported pFUnit directive @assertNotEqual (funit-lite supports: ...)`.

Line numbers: the output keeps the .pf line numbering (line N of the .F90 is line N of
the .pf) as long as the expansions fit in the 132-column limit; an expansion that needs
an extra continuation line shifts the following lines down until the next blank line of
the .pf, which is dropped to restore the numbering.
"""

import argparse
import os
import re
import sys
import tempfile

ASSERTIONS = [
    "assertEqual",
    "assertTrue",
    "assertFalse",
    "assertLessThan",
    "assertLessThanOrEqual",
    "assertGreaterThan",
    "assertGreaterThanOrEqual",
    "assertRelativelyEqual",
    "assertIsFinite",
]
CANONICAL = {name.lower(): name for name in ASSERTIONS}
SUPPORTED = ["@test", "@before", "@after"] + ["@" + name for name in ASSERTIONS]
MAX_COLUMNS = 132   # Fortran 2008 free-form line length
# pFUnit 4.x writes `@assertX(args)` as `call assertX(args, &`: `call ` in place of `@`.
# For the result to fit in 132 columns (gfortran rejects longer free-form lines), a
# directive line may have at most 128 columns (trailing blanks not counted).
MAX_DIRECTIVE_COLUMNS = MAX_COLUMNS - len("call ") + len("@")
CONTINUATION_MESSAGE = "pFUnit 4.x requires @%s on one line (no '&' continuation)"
MAX_NAME = 63       # Fortran 2008 name length

RE_DIRECTIVE = re.compile(r"^(\s*)@(\w*)(.*)$")
RE_MODULE = re.compile(r"^\s*module\s+(\w+)\s*(!.*)?$", re.IGNORECASE)
RE_SUBROUTINE = re.compile(
    r"^\s*subroutine\s+(\w+)\s*(\((?P<args>[^)]*)\))?\s*(!.*)?$", re.IGNORECASE)
RE_BLANK_OR_COMMENT = re.compile(r"^\s*(!.*)?$")
RE_USE_FUNIT = re.compile(
    r"^\s*use\s*(,\s*non_intrinsic\s*::\s*|::\s*|\s)\s*funit\s*(,.*)?(!.*)?$", re.IGNORECASE)


class PfError(Exception):
    """A problem in the .pf file, reported as `file:line: message`."""


def supported_list():
    return ", ".join(SUPPORTED)


def fail(path, lineno, message):
    raise PfError("%s:%d: %s" % (path, lineno, message))


class Directive:
    """An `@assertX(...)` on lines[first] (0-based); `last` == `first` (no continuation)."""

    def __init__(self, name, first, last, close_col):
        self.name = name            # canonical assertion name
        self.first = first          # index of the line holding the `@`
        self.last = last            # index of the line holding the closing `)`
        self.close_col = close_col  # column of the closing `)` in lines[last]


def scan_assertion(path, lines, first, name_end, name):
    """Find the argument list of the assertion `@name(...)` on lines[first].

    `name_end` is the column just after the directive name.  pFUnit 4.x only expands an
    assertion whose line matches `@assertX(...)` ending in `)`, so the whole directive must
    be on one line: a `&` continuation (in the arguments or in a character literal) is an
    error, as is anything after the closing `)`.  Character literals are skipped, so
    parentheses, `&` and `!` inside them do not count.  Returns (first, close_column).
    """
    lineno = first + 1
    line = lines[first]
    depth = 0           # parenthesis depth; 0 before the opening '('
    quote = None        # delimiter of the character literal being scanned
    opened = False
    has_args = False
    col = name_end
    while col < len(line):
        ch = line[col]
        if quote:
            if ch == quote:
                if line[col + 1:col + 2] == quote:
                    col += 1          # doubled delimiter inside the literal
                else:
                    quote = None
            elif ch == "&" and line[col + 1:].strip() == "":
                fail(path, lineno, CONTINUATION_MESSAGE % name)
        elif ch.isspace():
            pass
        elif ch == "&":
            fail(path, lineno, CONTINUATION_MESSAGE % name)
        elif ch == "!":
            break                     # a comment before the closing ')'
        elif not opened:
            if ch != "(":
                fail(path, lineno, "expected '(' after @%s" % name)
            opened = True
            depth = 1
        else:
            if ch in "'\"":
                quote = ch
            elif ch == "(":
                depth += 1
            elif ch == ")":
                depth -= 1
                if depth == 0:
                    rest = line[col + 1:].strip()
                    if rest:
                        fail(path, lineno,
                             "unexpected text after the closing ')' of @%s: %r (pFUnit "
                             "rejects it too; put comments on their own line)" % (name, rest))
                    if not has_args:
                        fail(path, lineno, "@%s without arguments" % name)
                    return first, col
            has_args = True
        col += 1
    if quote:
        fail(path, lineno, "unterminated character literal in @%s" % name)
    fail(path, lineno, "@%s is missing its closing ')' (pFUnit 4.x requires the whole "
         "assertion on one line)" % name)


def expand_assertion(path, lines, d, out_name):
    """Output lines for directive `d`; usually as many as it spans in the .pf."""
    lineno = d.first + 1
    out = list(lines[d.first:d.last + 1])
    # `@assertX` becomes `call assertX` on the first line
    m = RE_DIRECTIVE.match(out[0])
    head = m.group(1) + "call " + d.name
    close_col = d.close_col
    if d.last == d.first:
        close_col += len(head) - (len(m.group(1)) + 1 + len(m.group(2)))
    out[0] = head + m.group(3)
    # the location goes before the closing ')', then the early return
    before = out[-1][:close_col].rstrip()
    tail = ", location=SourceLocation('%s', %d)); if (anyExceptions()) return" % (
        out_name, lineno)
    if len(before) + len(tail) <= MAX_COLUMNS:
        out[-1] = before + tail
    else:
        out[-1] = before + " &"
        out.append(m.group(1) + "  & " + tail)
    for k, text in enumerate(out):
        if len(text) > MAX_COLUMNS:
            stripped = text.lstrip()
            if len(stripped) + 1 <= MAX_COLUMNS:
                out[k] = " " + stripped
            else:
                fail(path, lineno,
                     "line longer than %d columns after expansion; shorten the assertion"
                     % MAX_COLUMNS)
    return out


def process(in_path, out_path):
    with open(in_path, encoding="utf-8") as f:
        lines = f.read().splitlines()
    pf_name = os.path.basename(in_path)
    base = os.path.splitext(pf_name)[0]

    module = None
    tests = []          # (name, line)
    before = None
    after = None
    out = []
    shift = 0           # output lines minus input lines so far
    pending = None      # ('test'|'before'|'after', directive line number)

    i = 0
    while i < len(lines):
        line = lines[i]
        lineno = i + 1

        if pending is not None and not RE_BLANK_OR_COMMENT.match(line):
            kind, at = pending
            m = RE_SUBROUTINE.match(line)
            if not m:
                fail(in_path, lineno, "expected 'subroutine <name>()' after @%s (line %d)"
                     % (kind, at))
            if m.group("args") is not None and m.group("args").strip():
                fail(in_path, lineno, "@%s procedure %s must have no dummy arguments "
                     "(pFUnit TestCase classes are not supported by funit-lite)"
                     % (kind, m.group(1)))
            name = m.group(1)
            if kind == "test":
                if name.lower() in (t[0].lower() for t in tests):
                    fail(in_path, lineno, "duplicate test %s" % name)
                tests.append((name, at))
            elif kind == "before":
                before = name
            else:
                after = name
            pending = None

        dm = RE_DIRECTIVE.match(line)
        if dm:
            width = len(line.rstrip())
            if width > MAX_DIRECTIVE_COLUMNS:
                fail(in_path, lineno, "directive line is %d columns long, the limit is %d: "
                     "pFUnit 4.x writes it with 'call ' in place of '@' and the result must "
                     "fit in %d columns (shorten it, e.g. with a local variable)"
                     % (width, MAX_DIRECTIVE_COLUMNS, MAX_COLUMNS))
            if pending is not None:
                fail(in_path, lineno, "directive @%s where the subroutine of @%s (line %d) "
                     "was expected" % (dm.group(2), pending[0], pending[1]))
            word = dm.group(2)
            key = word.lower()
            rest = dm.group(3)
            if key in ("test", "before", "after"):
                if rest.strip():
                    if key == "test" and rest.lstrip().startswith("("):
                        fail(in_path, lineno, "@test arguments are not supported by "
                             "funit-lite: @test%s" % rest)
                    fail(in_path, lineno, "unexpected text after @%s: %r" % (word, rest))
                if key == "before" and before is not None:
                    fail(in_path, lineno, "more than one @before")
                if key == "after" and after is not None:
                    fail(in_path, lineno, "more than one @after")
                if module is None:
                    fail(in_path, lineno, "@%s before the 'module' statement" % word)
                pending = (key, lineno)
                out.append(dm.group(1) + "!@" + word + rest)
                i += 1
                continue
            if key in CANONICAL:
                last, close_col = scan_assertion(in_path, lines, i,
                                                 len(dm.group(1)) + 1 + len(word), word)
                d = Directive(CANONICAL[key], i, last, close_col)
                expanded = expand_assertion(in_path, lines, d, pf_name)
                shift += len(expanded) - (last - i + 1)
                out.extend(expanded)
                i = last + 1
                continue
            fail(in_path, lineno, "unsupported pFUnit directive @%s (funit-lite supports: "
                 "%s)" % (word, supported_list()))

        mm = RE_MODULE.match(line)
        if mm and mm.group(1).lower() != "procedure":
            if mm.group(2):
                fail(in_path, lineno, "comment on the 'module' line: pFUnit 4.x then does not "
                     "recognise the module and the tests fail to link; put the comment on "
                     "its own line")
            if module is not None:
                fail(in_path, lineno, "more than one module in a .pf file (funit-lite "
                     "expects exactly one)")
            module = mm.group(1)
            if module.lower() != base.lower():
                fail(in_path, lineno, "module %s must be named after its file (%s), as "
                     "pFUnit's add_pfunit_ctest expects" % (module, base))

        if shift > 0 and line.strip() == "":
            shift -= 1      # drop a blank line to restore the .pf line numbering
        else:
            out.append(line)
        i += 1

    if pending is not None:
        fail(in_path, pending[1], "@%s is not followed by a subroutine" % pending[0])
    if module is None:
        fail(in_path, 1, "no 'module <name>' statement found")
    if not tests:
        fail(in_path, 1, "no @test procedures found")
    if not any(RE_USE_FUNIT.match(line) for line in lines):
        fail(in_path, 1, "module %s does not 'use funit'" % module)
    for name in ("wrap_" + module, module + "_suite"):
        if len(name) > MAX_NAME:
            fail(in_path, 1, "module name too long for the generated name %s" % name)

    out.extend(registration_module(pf_name, module, tests, before, after))
    write_atomically(out_path, out)


def registration_module(pf_name, module, tests, before, after):
    """`wrap_<module>` with `<module>_suite(n_passed, n_failed)` running every test."""
    used = [t[0] for t in tests] + [p for p in (before, after) if p]
    out = [
        "",
        "! ---- generated by funit-lite (tests/funit_lite/funitproc_lite.py) from %s ----"
        % pf_name,
        "!> Runs the tests of %s in file order." % module,
        "module wrap_%s" % module,
        "  use funit, only: funit_lite_run_test",
    ]
    out += continued("  use %s, only: " % module, used)
    out += [
        "  implicit none",
        "  private",
        "  public :: %s_suite" % module,
        "contains",
        "  !> Run every @test of %s, counting passed and failed tests." % module,
        "  subroutine %s_suite(n_passed, n_failed)" % module,
        "    integer, intent(inout) :: n_passed !! tests passed so far",
        "    integer, intent(inout) :: n_failed !! tests failed so far",
    ]
    for name, _ in tests:
        out.append("    call funit_lite_run_test('%s', &" % pf_name)
        out.append("         '%s', %s, &" % (name, name))
        extra = ""
        if before:
            extra += ", before=" + before
        if after:
            extra += ", after=" + after
        out.append("         n_passed, n_failed%s)" % extra)
    out += [
        "  end subroutine %s_suite" % module,
        "end module wrap_%s" % module,
    ]
    return out


def continued(head, names):
    """`head` followed by comma-separated names, wrapped with '&' continuation."""
    out = []
    line = head
    for k, name in enumerate(names):
        piece = name + ("," if k + 1 < len(names) else "")
        if len(line) + len(piece) + 3 > MAX_COLUMNS:
            out.append(line.rstrip() + " &")
            line = "      "
        line += piece + " "
    out.append(line.rstrip())
    return out


def driver(out_path, modules, extra_use, extra_init, extra_final):
    out = [
        "! ---- generated by funit-lite (tests/funit_lite/funitproc_lite.py) ----",
        "!> Runs every test suite, prints `N passed, N failed` and fails when any test did.",
        "program funit_lite_main",
        "  use, intrinsic :: iso_fortran_env, only: output_unit",
    ]
    for m in modules:
        out.append("  use wrap_%s, only: %s_suite" % (m, m))
    if extra_use:
        out.append("  use %s" % extra_use)
    out += [
        "  implicit none",
        "  integer :: funit_lite_passed, funit_lite_failed",
        "",
        "  funit_lite_passed = 0",
        "  funit_lite_failed = 0",
    ]
    if extra_init:
        out.append("  call %s()" % extra_init)
    for m in modules:
        out.append("  call %s_suite(funit_lite_passed, funit_lite_failed)" % m)
    if extra_final:
        out.append("  call %s()" % extra_final)
    out += [
        "  write(output_unit, '(i0, a, i0, a)') funit_lite_passed, ' passed, ', &",
        "    funit_lite_failed, ' failed'",
        "  flush(output_unit)",
        "  if (funit_lite_failed > 0) error stop 1",
        "end program funit_lite_main",
    ]
    write_atomically(out_path, out)


def write_atomically(path, lines):
    """Write only when the content changes (avoids needless rebuilds), atomically."""
    text = "\n".join(lines) + "\n"
    try:
        with open(path, encoding="utf-8") as f:
            if f.read() == text:
                os.utime(path, None)   # keep the build tool's notion of "up to date"
                return
    except OSError:
        pass
    directory = os.path.dirname(os.path.abspath(path))
    os.makedirs(directory, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=".funit_lite_")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def fortran_name(value):
    if not re.fullmatch(r"[A-Za-z]\w{0,62}", value):
        raise argparse.ArgumentTypeError("not a Fortran name: %r" % value)
    return value


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("process", help="preprocess one .pf file")
    p.add_argument("input")
    p.add_argument("output")
    d = sub.add_parser("driver", help="write the driver program")
    d.add_argument("--output", required=True)
    d.add_argument("--extra-use", type=fortran_name)
    d.add_argument("--extra-initialize", type=fortran_name)
    d.add_argument("--extra-finalize", type=fortran_name)
    d.add_argument("modules", nargs="+", type=fortran_name)
    args = parser.parse_args(argv)
    try:
        if args.command == "process":
            process(args.input, args.output)
        else:
            driver(args.output, args.modules, args.extra_use, args.extra_initialize,
                   args.extra_finalize)
    except PfError as e:
        print(e, file=sys.stderr)
        return 1
    except OSError as e:
        print(e, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
