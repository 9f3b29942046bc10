#!/usr/bin/env python3
"""Import circles between the modules of each crate.

    scripts/module-cycles.py [CRATE_DIR...]      (default: every crates/*)

For every module (one file) of a crate, the modules it names: `use crate::..`, `use super::..`,
`use self::..` and the same paths inside code, paths through a module imported by name
(`use crate::adapters;` then `adapters::englobe::..`), and a parent's paths into its own child
modules (`ply::load` in `mesh/mod.rs`). A path is resolved to the deepest module it names, and an
item a module re-exports (`pub use cost::CostImage;` in `lib.rs`) to the module that defines it, so
that `crate::CostImage` counts as an import of `cost`, not of the crate root. Comments are ignored;
test modules count (a circle through a test is still a circle).

Prints every strongly connected group of two or more modules, with one import of each edge inside
it, and exits with 1 if there is any. A group that contains a parent (`mod.rs`, `lib.rs`) and its
child is reported as such: the child uses something the parent defines while the parent calls into
the child, or re-exports it. The cure is the same: move what both use into a module below both.
Inside such a group, the circles left between siblings once the parent-child imports are set
aside are listed too, since a family circle can hide them.
"""

import re
import sys
from pathlib import Path

IDENT = r"[A-Za-z_][A-Za-z0-9_]*"


def strip_comments(text):
    """The source without comments and string literals (kept as empty strings)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    if text[i] == "\n":
                        out.append("\n")
                    i += 1
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and (i == 0 or not re.match(r"\w", text[i - 1])):
            hashes = re.match(r'r(#*)"', text[i:]).group(1)
            end = text.find('"' + hashes, i + 2 + len(hashes))
            end = n if end < 0 else end + 1 + len(hashes)
            out.append('""' + "\n" * text.count("\n", i, end))
            i = end
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j + 1
        elif c == "'" and re.match(r"'(\\.|[^\\'])'", text[i:i + 4]) or text.startswith("'\\u{", i):
            j = text.find("'", i + 1)
            while text[j - 1] == "\\" and text[j - 2] != "\\":
                j = text.find("'", j + 1)
            out.append("' '")
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def expand_use_tree(tree):
    """`a::{b, c::{self, d as e}}` -> [(['a','b'], 'b'), (['a','c'], 'c'), (['a','c','d'], 'e')]:
    each path with the name it is imported under."""
    tree = re.sub(r"\s+as\s+", "@", tree)
    tree = re.sub(r"\s+", "", tree)
    results = []

    def walk(prefix, s):
        depth, start, parts = 0, 0, []
        for k, ch in enumerate(s):
            if ch == "{":
                depth += 1
            elif ch == "}":
                depth -= 1
            elif ch == "," and depth == 0:
                parts.append(s[start:k])
                start = k + 1
        parts.append(s[start:])
        for part in parts:
            if not part:
                continue
            brace = part.find("{")
            if brace >= 0:
                head = [p for p in part[:brace].split("::") if p]
                walk(prefix + head, part[brace + 1:part.rindex("}")])
                continue
            part, _, alias = part.partition("@")
            segs = prefix + [p for p in part.split("::") if p]
            if len(segs) > 1 and segs[-1] == "self":
                segs = segs[:-1]
            results.append((segs, alias or segs[-1]))

    walk([], tree)
    return results


class Crate:
    def __init__(self, src):
        self.src = src
        self.files = {}  # module path (tuple) -> file
        roots = [p for p in ("lib.rs", "main.rs") if (src / p).exists()]
        self.root_file = src / roots[0]
        for f in sorted(src.rglob("*.rs")):
            rel = f.relative_to(src)
            if rel.parts[0] == "bin" or (rel.name == "main.rs" and len(rel.parts) == 1 and len(roots) == 2):
                continue
            parts = list(rel.with_suffix("").parts)
            if parts[-1] in ("mod", "lib", "main"):
                parts = parts[:-1]
            self.files[tuple(parts)] = f
        self.text = {m: strip_comments(f.read_text()) for m, f in self.files.items()}
        self.reexports = {m: self.find_reexports(m) for m in self.files}

    def name(self, module):
        return "crate::" + "::".join(module) if module else "crate"

    def find_reexports(self, module):
        """Name -> absolute path, for what the module's `pub use` lines re-export."""
        out = {}
        for m in re.finditer(r"\bpub(\([^)]*\))?\s+use\s+([^;]+);", self.text[module]):
            for segs, name in expand_use_tree(m.group(2)):
                absolute = self.absolute(module, segs)
                if absolute and name != "*":
                    out[name] = absolute
        return out

    def absolute(self, module, segs):
        """Absolute segments of a path written in `module`, or None if outside the crate."""
        segs = list(segs)
        if not segs:
            return None
        if segs[0] == "crate":
            return segs[1:]
        base = list(module)
        if segs[0] in ("self", "super"):
            while segs and segs[0] in ("self", "super"):
                if segs.pop(0) == "super":
                    if not base:
                        return None
                    base.pop()
            return base + segs
        if tuple(base + segs[:1]) in self.files:  # a child module by its bare name
            return base + segs
        return None

    def resolve(self, segs, seen=None):
        """The module an absolute path names: its deepest module, through re-exports."""
        seen = seen or set()
        for k in range(len(segs), -1, -1):
            if tuple(segs[:k]) in self.files:
                module = tuple(segs[:k])
                rest = segs[k:]
                if rest and rest[0] in self.reexports[module] and (module, rest[0]) not in seen:
                    seen.add((module, rest[0]))
                    return self.resolve(self.reexports[module][rest[0]] + rest[1:], seen)
                return module
        return None

    def imports(self, module):
        """Module -> where the import is, for each module that `module` names."""
        text = self.text[module]
        file = self.files[module].name
        found = {}
        aliases = {}  # a name imported by `use` that is a module -> that module
        # Inline modules (`mod tests { .. }`, at the end of a file): `super` in them is the file's
        # module and `self` is the inline module, which resolves to the file's module too.
        inline = [m.start() for m in re.finditer(r"\bmod\s+" + IDENT + r"\s*\{", text)]

        def scope(pos):
            return module + ("tests",) if any(start < pos for start in inline) else module

        def add(absolute, why):
            target = self.resolve(absolute) if absolute is not None else None
            if target is not None and target != module:
                found.setdefault(target, why)
            return target

        for m in re.finditer(r"\buse\s+([^;]+);", text):
            line = text.count("\n", 0, m.start()) + 1
            for segs, name in expand_use_tree(m.group(1)):
                absolute = self.absolute(scope(m.start()), segs)
                target = add(absolute, f"{file}:{line}: use {'::'.join(segs)}")
                if target is not None and tuple(absolute) == target:
                    aliases[name] = list(target)
        code = re.sub(r"\buse\s+[^;]+;", lambda m: "\n" * m.group(0).count("\n"), text)
        children = [child[-1] for child in self.files if child and child[:-1] == module]
        heads = ["crate", "super", "self"] + children + list(aliases)
        pattern = r"(?<![\w:])((?:" + "|".join(map(re.escape, heads)) + r")(?:::" + IDENT + r")+)"
        for m in re.finditer(pattern, code):
            segs = m.group(1).split("::")
            why = f"{file}:{code.count(chr(10), 0, m.start()) + 1}: {m.group(1)}"
            if segs[0] in aliases and segs[0] not in children:
                add(aliases[segs[0]] + segs[1:], why)
            else:
                add(self.absolute(scope(m.start()), segs), why)
        return found


def cycles(graph):
    """Strongly connected components of two or more nodes (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]
    sys.setrecursionlimit(10000)

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, {}):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                out.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def main():
    repo = Path(__file__).resolve().parent.parent
    dirs = [Path(a) for a in sys.argv[1:]] or sorted(p for p in (repo / "crates").iterdir() if (p / "src").is_dir())
    any_cycle = False
    for crate_dir in dirs:
        crate = Crate(crate_dir / "src")
        graph = {m: crate.imports(m) for m in crate.files}
        groups = cycles(graph)
        print(f"{crate_dir.name}: {len(crate.files)} modules, {len(groups)} circle(s)")
        for group in groups:
            any_cycle = True
            members = set(group)
            family = any(a != b and b[: len(a)] == a for a in group for b in group)
            kind = " (a parent and its child)" if family else ""
            print(f"  circle{kind}: " + ", ".join(crate.name(m) for m in group))
            for a in group:
                for b, why in sorted(graph[a].items()):
                    if b in members:
                        print(f"    {crate.name(a)} -> {crate.name(b)}    {why}")
            if family:
                # What is left once each parent's imports of its descendants and theirs of it are
                # set aside: circles between siblings, hidden inside the family one.
                related = lambda a, b: a[: len(b)] == b or b[: len(a)] == a
                inner = {a: {b: w for b, w in graph[a].items() if b in members and not related(a, b)} for a in group}
                for sub in cycles(inner):
                    print("    of which, between siblings: " + ", ".join(crate.name(m) for m in sub))
    sys.exit(1 if any_cycle else 0)


if __name__ == "__main__":
    main()
