"""The ``hystkit-cli`` directive: the command-line reference, read from hystkit's own parser.

``.. hystkit-cli::`` builds the parser ``hystkit`` itself builds (``hystkit.cli._main._parser``,
every ``cmd_*`` module registered), resolves its deferred values (choices, defaults and help
texts that need the model families: ``format_help`` computes them) and writes one section per
subcommand, and per sub-subcommand (``datasets list``, ``table 5.4``): its summary, usage, and
each option of each argument group with its help, choices and default. Nothing here names a
subcommand or an option, so a new one appears in the reference with no edit.
"""

from __future__ import annotations

import argparse

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective

USAGE_WIDTH = 88  # columns of the usage lines, whatever the terminal building the site


def _subparsers(parser: argparse.ArgumentParser) -> argparse._SubParsersAction | None:
    return next((a for a in parser._actions if isinstance(a, argparse._SubParsersAction)),
                None)


def _summaries(action: argparse._SubParsersAction) -> dict[str, str]:
    """Each subcommand's one-line help, as ``hystkit --help`` lists it."""
    return {a.dest: a.help or "" for a in action._choices_actions}


def _paragraph(text: str) -> nodes.paragraph:
    return nodes.paragraph(text, text)


def _says_something(default: object) -> bool:
    """A default worth printing: not None, False, SUPPRESS or an empty string or sequence."""
    if default is None or default is False or default is argparse.SUPPRESS:
        return False
    return not (isinstance(default, (str, tuple, list)) and len(default) == 0)


def _option_item(parser: argparse.ArgumentParser, action: argparse.Action,
                 ) -> nodes.definition_list_item:
    formatter = parser._get_formatter()
    term_text = formatter._format_action_invocation(action)
    body = nodes.definition()
    if action.help:
        body += _paragraph(" ".join(formatter._expand_help(action).split()))
    help_text = (action.help or "").lower()
    facts = []
    if (action.choices is not None and not isinstance(action, argparse._SubParsersAction)
            and "{" not in term_text):  # choices the metavar hides
        facts.append("choices: " + ", ".join(str(c) for c in action.choices))
    if action.option_strings and action.nargs != 0 and "default" not in help_text \
            and _says_something(action.default):
        facts.append(f"default: {action.default}")
    if action.required and action.option_strings:
        facts.append("required")
    if facts:
        body += _paragraph("; ".join(facts))
    return nodes.definition_list_item("", nodes.term("", "", nodes.literal(term_text, term_text)),
                                      body)


class HystkitCli(SphinxDirective):
    has_content = False

    def run(self) -> list[nodes.Node]:
        from hystkit.cli._main import _parser

        parser = _parser()
        return [*self._body(parser, ""), *self._children(parser, "hystkit")]

    def _body(self, parser: argparse.ArgumentParser, summary: str) -> list[nodes.Node]:
        """Summary, description, usage and the options of `parser`, group by group."""
        parser.format_help()  # its deferred choices, defaults and help texts, as --help shows
        body: list[nodes.Node] = []
        if summary:
            body.append(_paragraph(summary))
        if parser.description and parser.description != summary:
            body.append(_paragraph(" ".join(parser.description.split())))
        formatter = parser.formatter_class(prog=parser.prog, width=USAGE_WIDTH)
        formatter.add_usage(parser.usage, parser._actions, parser._mutually_exclusive_groups)
        usage = formatter.format_help().strip()
        body.append(nodes.literal_block(usage, usage))
        for group in parser._action_groups:
            actions = [a for a in group._group_actions if a.help is not argparse.SUPPRESS
                       and not isinstance(a, argparse._SubParsersAction)]
            if not actions:
                continue
            body.append(nodes.rubric(group.title, group.title))
            if group.description:
                body.append(_paragraph(" ".join(group.description.split())))
            body.append(nodes.definition_list("", *(_option_item(parser, a) for a in actions)))
        if parser.epilog:
            body.append(_paragraph(" ".join(parser.epilog.split())))
        return body

    def _children(self, parser: argparse.ArgumentParser, name: str) -> list[nodes.section]:
        """One section per subcommand of `parser` (named `name`), its own subcommands nested."""
        sub = _subparsers(parser)
        if sub is None:
            return []
        summaries = _summaries(sub)
        sections = []
        for command, subparser in sub.choices.items():
            full = f"{name} {command}"
            ident = nodes.make_id("cli " + full.removeprefix("hystkit "))
            section = nodes.section(ids=[ident], names=[ident])
            self.state.document.note_explicit_target(section)
            section += nodes.title(full, "", nodes.literal(full, full))
            section.extend(self._body(subparser, summaries.get(command, "")))
            section.extend(self._children(subparser, full))
            sections.append(section)
        return sections


def setup(app: Sphinx) -> dict[str, object]:
    app.add_directive("hystkit-cli", HystkitCli)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
