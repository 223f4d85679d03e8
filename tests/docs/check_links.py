#!/usr/bin/env python3
"""Checks the documentation's front door and its links.

  check_links.py [REPO_ROOT]

Fails (exit status 1, one line per problem on stderr) when README.md has 300 lines or more, or
when a relative markdown link or image in README.md or docs/*.md names a file that does not
exist. Links to http(s), mailto and pure anchors (#...) are not checked; an anchor after a file
name (docs/x.md#part) is dropped, the file must exist. Fenced code blocks and inline code spans
are skipped, so `[a](b)` inside code is not a link. Standard library only.
"""

import pathlib
import re
import sys

README_MAX_LINES = 300  # README.md must stay under this many lines

# [text](target) or ![alt](target), text possibly over several lines, one level of nested
# brackets in the text (a link inside an image link), an optional "title" after the target.
INLINE_LINK = re.compile(
    r'!?\[(?:[^\[\]]|\[[^\[\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+"[^"]*")?\s*\)')
# [label]: target (reference-style definitions), at the start of a line.
REFERENCE_DEF = re.compile(r'^ {0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+"[^"]*")?\s*$', re.M)
FENCE = re.compile(r'^ {0,3}(```|~~~)')
CODE_SPAN = re.compile(r'(`+)(?:(?!\1).)+?\1', re.S)


def strip_code(text):
    """The text with fenced code blocks and inline code spans blanked (line count kept)."""
    lines, fence = [], None
    for line in text.split('\n'):
        m = FENCE.match(line)
        if fence is None and m:
            fence = m.group(1)
            lines.append('')
        elif fence is not None:
            if line.strip().startswith(fence):
                fence = None
            lines.append('')
        else:
            lines.append(line)
    return CODE_SPAN.sub(lambda m: ' ' * len(m.group(0)), '\n'.join(lines))


def is_external(target):
    return re.match(r'^[a-zA-Z][a-zA-Z0-9+.-]*:', target) is not None or target.startswith('//')


def link_problems(md_file, root):
    """One message per relative link of md_file whose file does not exist."""
    text = strip_code(md_file.read_text(encoding='utf-8'))
    problems = []
    targets = [(m.start(), m.group(1)) for m in INLINE_LINK.finditer(text)]
    targets += [(m.start(), m.group(1)) for m in REFERENCE_DEF.finditer(text)]
    for pos, target in sorted(targets):
        if is_external(target) or target.startswith('#'):
            continue
        path = target.split('#', 1)[0].split('?', 1)[0]
        if not path:
            continue
        resolved = (md_file.parent / path).resolve()
        if not resolved.exists():
            line = text.count('\n', 0, pos) + 1
            rel = md_file.relative_to(root)
            problems.append(f'{rel}:{line}: link to {target}: no such file ({path})')
    return problems


def main(argv):
    root = pathlib.Path(argv[1] if len(argv) > 1 else pathlib.Path(__file__).parents[2])
    root = root.resolve()
    readme = root / 'README.md'
    if not readme.is_file():
        print(f'{readme}: missing', file=sys.stderr)
        return 1
    problems = []
    n_lines = len(readme.read_text(encoding='utf-8').splitlines())
    if n_lines >= README_MAX_LINES:
        problems.append(f'README.md: {n_lines} lines, must be under {README_MAX_LINES}'
                        ' (move details to docs/)')
    files = [readme] + sorted((root / 'docs').glob('*.md'))
    for md_file in files:
        problems += link_problems(md_file, root)
    for p in problems:
        print(p, file=sys.stderr)
    print(f'checked {len(files)} files, README.md {n_lines} lines, {len(problems)} problems')
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
