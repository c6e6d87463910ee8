r"""Docstrings read in a terminal: a command's ``--help`` is its module docstring, written for the documentation site
in reStructuredText with TeX maths, and shown here as plain text.

:func:`plain` turns the markup into what it stands for: a literal ````x```` and a cross-reference
``:func:`~a.b.c``` into ``x`` and ``c`` (``a.b.c`` without the tilde), maths (``:math:`\delta_\mathrm{max}```, a
``.. math::`` block) into a readable line (``δ_max``, :func:`tex_plain`), ``text::`` into ``text:``.
:class:`HelpFormatter` is the argparse formatter of :class:`sinterheat.cli.OneLineParser`: it renders descriptions,
epilogs and option help with :func:`plain` and keeps the paragraphs, list items and indented blocks of the docstring
instead of running them into one paragraph.
"""

from __future__ import annotations

import argparse
import inspect
import re
import textwrap

GREEK = {name: chr(code) for name, code in (
    ("alpha", 0x3B1), ("beta", 0x3B2), ("gamma", 0x3B3), ("delta", 0x3B4), ("epsilon", 0x3B5), ("varepsilon", 0x3B5),
    ("zeta", 0x3B6), ("eta", 0x3B7), ("theta", 0x3B8), ("vartheta", 0x3D1), ("iota", 0x3B9), ("kappa", 0x3BA),
    ("lambda", 0x3BB), ("mu", 0x3BC), ("nu", 0x3BD), ("xi", 0x3BE), ("pi", 0x3C0), ("rho", 0x3C1), ("varrho", 0x3F1),
    ("sigma", 0x3C3), ("tau", 0x3C4), ("upsilon", 0x3C5), ("phi", 0x3C6), ("varphi", 0x3C6), ("chi", 0x3C7),
    ("psi", 0x3C8), ("omega", 0x3C9), ("Gamma", 0x393), ("Delta", 0x394), ("Theta", 0x398), ("Lambda", 0x39B),
    ("Xi", 0x39E), ("Pi", 0x3A0), ("Sigma", 0x3A3), ("Phi", 0x3A6), ("Psi", 0x3A8), ("Omega", 0x3A9))}
SYMBOLS = {**GREEK, "cdot": "·", "times": "×", "otimes": "⊗", "le": "≤", "leq": "≤", "ge": "≥", "geq": "≥",
           "ne": "≠", "neq": "≠", "approx": "≈", "sim": "~", "ll": "≪", "gg": "≫", "pm": "±", "infty": "∞",
           "sum": "Σ", "prod": "Π", "int": "∫", "partial": "∂", "nabla": "∇", "to": "→", "rightarrow": "→",
           "ldots": "...", "cdots": "...", "dots": "...", "in": "∈", "propto": "∝", "equiv": "≡"}
FONTS = ("mathrm", "mathbf", "mathit", "mathsf", "mathtt", "mathcal", "boldsymbol", "bm", "text", "textrm",
         "operatorname", "mathrel", "mathop", "mathbin", "hat", "bar", "vec", "tilde", "overline")
SIZES = ("left", "right", "big", "Big", "bigg", "Bigg", "bigl", "bigr", "Bigl", "Bigr", "displaystyle")
SPACES = {",": " ", ";": " ", ":": " ", "!": "", " ": " ", "quad": "  ", "qquad": "    "}
GLUED = ("Delta", "partial")  # written against the symbol that follows: Δt, ∂T


def _argument(tex: str, i: int) -> tuple[str, int]:
    """The argument of a TeX command at ``tex[i:]`` (after spaces): a braced group's content, a command, or one
    character; and where the text after it starts."""
    while i < len(tex) and tex[i] == " ":
        i += 1
    if i >= len(tex):
        return "", i
    if tex[i] == "{":
        depth = 0
        for k in range(i, len(tex)):
            depth += {"{": 1, "}": -1}.get(tex[k], 0)
            if depth == 0:
                return tex[i + 1:k], k + 1
        return tex[i + 1:], len(tex)
    if tex[i] == "\\":
        name = re.match(r"\\([A-Za-z]+|.)", tex[i:]).group(0)
        if name[1:] in FONTS or name[1:] in ("frac", "dfrac", "tfrac", "sqrt", "dot", "ddot"):  # with its arguments
            end = i + len(name)
            for _ in range(2 if "frac" in name else 1):
                end = _argument(tex, end)[1]
            return tex[i:end], end
        return name, i + len(name)
    return tex[i], i + 1


def _grouped(text: str) -> str:
    """``text`` in parentheses unless it is one symbol, a number, or already one parenthesised group."""
    if re.fullmatch(r"-?[\w.'\u0307\u0308√]+", text) or re.fullmatch(r"\((?:[^()]|\([^()]*\))*\)", text):
        return text
    return f"({text})"


def tex_plain(tex: str) -> str:
    """TeX maths as one line of plain text: Greek letters and operators as their Unicode signs, font and size
    commands dropped (their argument kept), a fraction as ``a/b`` (an argument of more than one symbol in
    parentheses), a square root as ``√x``, a dotted symbol with a combining dot, a sub- or superscript of more than
    one symbol in parentheses after its ``_`` or ``^``, an equation's tag as ``(22)`` set apart; any other command by
    its name (the operators ``max``, ``ln`` ...).

    Parameters
    ----------
    tex : str
        The maths, as in a ``:math:`` role.

    Returns
    -------
    str
        The plain text.
    """
    out, i = [], 0
    while i < len(tex):
        char = tex[i]
        if char == "\\":
            name = re.match(r"\\([A-Za-z]+|.)", tex[i:]).group(1)
            i += 1 + len(name)
            if name in ("frac", "dfrac", "tfrac"):
                top, i = _argument(tex, i)
                bottom, i = _argument(tex, i)
                out.append(f"{_grouped(tex_plain(top))}/{_grouped(tex_plain(bottom))}")
            elif name == "sqrt":
                arg, i = _argument(tex, i)
                out.append(f"√{_grouped(tex_plain(arg))}")
            elif name in ("dot", "ddot"):
                arg, i = _argument(tex, i)
                out.append(tex_plain(arg) + ("\u0307" if name == "dot" else "\u0308"))
            elif name == "tag":
                arg, i = _argument(tex, i)
                out.append(f"\0({arg})")  # set apart once the spaces are collapsed
            elif name in FONTS:
                arg, i = _argument(tex, i)
                out.append(tex_plain(arg))
            elif name in SIZES:
                pass
            elif name in SPACES:
                out.append(SPACES[name])
            elif name == "\\":
                out.append("; ")
            else:
                out.append(SYMBOLS.get(name, name))
                if name in GLUED and tex[i:i + 1] == " ":
                    i += 1  # TeX ignores the space after a command word: Δt, not Δ t
        elif char in "_^":
            arg, i = _argument(tex, i + 1)
            out.append(char + _grouped(tex_plain(arg)))
        elif char in "{}":
            i += 1
        else:
            out.append(char)
            i += 1
    return re.sub(r" {2,}", " ", "".join(out)).strip().replace(" \0", "\0").replace("\0", "    ")


_ROLE = re.compile(r":(?:[\w-]+:)?([\w-]+):`([^`]*)`", re.S)


def _role(match) -> str:
    role, content = match.group(1), " ".join(match.group(2).split())
    if role == "math":
        return tex_plain(content)
    titled = re.fullmatch(r"(.*?)\s*<([^>]*)>", content)
    if titled:
        return titled.group(1)
    return content[1:].rpartition(".")[2] if content.startswith("~") else content.lstrip("!")


def plain(text: str) -> str:
    """A docstring (reStructuredText with TeX maths) as plain text for a terminal (module docstring): its paragraphs,
    list items and indented blocks as written, the markup rendered.

    Parameters
    ----------
    text : str
        The docstring (its indentation is removed first, as ``inspect.cleandoc`` does).

    Returns
    -------
    str
        The text without markup.
    """
    lines, out, math_indent = inspect.cleandoc(text or "").splitlines(), [], None
    for line in lines:
        indent = len(line) - len(line.lstrip())
        if math_indent is not None:
            if not line.strip() or indent > math_indent:
                out.append(" " * (math_indent + 4) + tex_plain(line.strip()) if line.strip() else "")
                continue
            math_indent = None
        if line.strip().startswith(".. math::"):
            math_indent = indent
            if line.strip()[len(".. math::"):].strip():
                out.append(" " * (indent + 4) + tex_plain(line.strip()[len(".. math::"):]))
            continue
        out.append(line)
    text = "\n".join(out)
    text = _ROLE.sub(_role, text)
    text = re.sub(r"``(.+?)``", r"\1", text, flags=re.S)
    text = re.sub(r"(?<![\w`])`([^`\n]+)`(?![\w`])", r"\1", text)  # `default role`
    lines = [line if not line.endswith("::") else line[:-2].rstrip() if line[-3:-2] in (" ", "") else line[:-1]
             for line in (line.rstrip() for line in text.splitlines())]  # "text::" "text:", " ::" and "::" gone
    return re.sub(r"\n{3,}", "\n\n", "\n".join(lines)).strip("\n")


class HelpFormatter(argparse.HelpFormatter):
    """argparse's formatter for texts written as docstrings: descriptions and epilogs (argparse's ``_fill_text``) and
    option help (``_split_lines``) go through :func:`plain`; each paragraph and list item is wrapped to the terminal's
    width, and indented blocks (a usage block, displayed maths) are kept as they are.

    Parameters
    ----------
    prog : str
        The program's name.
    kwargs : object
        ``indent_increment``, ``max_help_position``, ``width`` of ``argparse.HelpFormatter``.
    """

    def _fill_text(self, text, width, indent):
        blocks, item = [], None  # item: (hanging indent, its lines) of the paragraph or list item being read

        def flush():
            if item is not None:
                blocks.append(textwrap.fill(" ".join(item[1]), width, initial_indent=indent,
                                            subsequent_indent=indent + item[0], break_on_hyphens=False,
                                            break_long_words=False))

        for line in plain(text).splitlines():
            marker = re.match(r"(?:\* |- |\d+[a-z]?\. )", line)
            depth = len(line) - len(line.lstrip())
            if item is not None and line.strip() and not marker and depth == len(item[0]):
                item[1].append(line.strip())  # the paragraph or list item goes on
                continue
            flush()
            item = None
            if not line.strip():
                blocks.append("")
            elif marker or depth == 0:
                item = (" " * (len(marker.group(0)) if marker else 0), [line.rstrip()])
            else:
                blocks.append(indent + line)  # an indented block: a usage block, displayed maths
        flush()
        return re.sub(r"\n{3,}", "\n\n", "\n".join(blocks)).strip("\n")

    def _split_lines(self, text, width):
        return textwrap.wrap(" ".join(plain(text).split()), width, break_on_hyphens=False)
