"""A command's ``--help`` shows its docstring as plain text (:mod:`sinterheat.help_text`): the markup written for
the documentation site (literals, cross-references, TeX maths) rendered, the paragraphs kept."""

import re

import pytest

from sinterheat import cli
from sinterheat.help_text import plain, tex_plain


@pytest.mark.parametrize("tex, text", [
    (r"\delta_\mathrm{max}", "δ_max"),
    (r"k_2(\delta_\mathrm{max})", "k_2(δ_max)"),
    (r"\gamma_0 \dot\delta", "γ_0 δ\u0307"),
    (r"\frac{\Delta t}{m}", "Δt/m"),
    (r"\frac{1}{2} \rho v^2", "1/2 ρ v^2"),
    (r"\frac{a + b}{c d}", "(a + b)/(c d)"),
    (r"\sqrt{\epsilon} \sum |K T|", "√ε Σ |K T|"),
    (r"(\mathrm{TOL}/D_0)^{1/(p K_d)}", "(TOL/D_0)^(1/(p K_d))"),
    (r"r^K - r^{K-1}", "r^K - r^(K-1)"),
    (r"C^{-1} A", "C^-1 A"),
    (r"A_{ii} \le \max_i 2 A_{ii} / C_i", "A_ii ≤ max_i 2 A_ii / C_i"),
    (r"T_{0,i} + \dot T_i \, (t - t_\mathrm{first})", "T_(0,i) + T\u0307_i (t - t_first)"),
    (r"\big(\phi F^{K-1} + (1 - \phi) F^L\big) \tag{22}", "(φ F^(K-1) + (1 - φ) F^L)    (22)"),
    (r"\mathbf{n} \times \boldsymbol{\omega}_i", "n × ω_i"),
])
def test_tex_as_plain_text(tex, text):
    assert tex_plain(tex) == text


def test_docstring_as_plain_text():
    doc = r"""Uses :func:`~dem.laws.contact.luding.relax_k1`, :mod:`dem.network` and :class:`the network <dem.network.heat.Network>`
    with ``--out DIR`` and :math:`k_1(T, t)`.

    Usage::

        python -m dem run SCENE

    .. math::

        C \frac{dT}{dt} = r - A T

    * an item
      that goes on
    """
    assert plain(doc) == ("Uses relax_k1, dem.network and the network\nwith --out DIR and k_1(T, t).\n\nUsage:\n\n"
                          "    python -m dem run SCENE\n\n    C dT/dt = r - A T\n\n* an item\n  that goes on")


def parsers():
    """Every parser of the packages' command lines (top level and sub-commands), by its program name."""
    from benchmarks import cli as benchmarks_cli
    from dem import cli as dem_cli
    from fem_neck import cli as fem_cli
    from verification import cli as verification_cli

    tops = [cli.build_parser("python -m dem", dem_cli.__doc__, dem_cli.COMMANDS, "dem.cli"),
            cli.build_parser("python -m fem_neck", fem_cli.__doc__, fem_cli.COMMAND_MODULES, "fem_neck.cli"),
            verification_cli.build_parser(), benchmarks_cli.build_parser()]
    found = {}
    for top in tops:
        found[top.prog] = top
        for action in top._subparsers._group_actions if top._subparsers else ():
            found.update({parser.prog: parser for parser in action.choices.values()})
    return found


MARKUP = re.compile(r"``|`|:[\w:-]+:`|\\[A-Za-z]|^\s*\.\. |::$", re.M)  # a literal, a role, TeX, a directive


def test_every_help_is_plain_text(monkeypatch):
    monkeypatch.setenv("COLUMNS", "100")
    helps = {prog: parser.format_help() for prog, parser in parsers().items()}
    assert len(helps) > 20
    assert {prog: MARKUP.findall(text) for prog, text in helps.items() if MARKUP.search(text)} == {}


def test_contact_help_reads_the_maths_and_keeps_paragraphs(monkeypatch):
    monkeypatch.setenv("COLUMNS", "200")
    text = parsers()["python -m dem contact"].format_help()
    assert text.count("\n\n") >= 4  # usage, the docstring's four paragraphs, the options
    text = " ".join(text.split())
    assert "k2 = k_2(δ_max), kc = k_c(T, t, δ_max) (all in N/m)" in text
    assert "(eq. 12, dem.laws.contact.state.sintering.relax_k1; cooling freezes at once)" in text
