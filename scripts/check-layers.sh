#!/usr/bin/env bash
# Checks the layering of src/ (ARCHITECTURE.md): the dependencies that must
# never exist. Run by .ci/run before the build; run it yourself after moving
# code. Prints every offending file:line with the rule it breaks and exits 1,
# or prints one line and exits 0.
#
#   src/spec/            knows no device, no screen, no scene and no CPU twin:
#                        no crate::gpu, crate::stages, crate::render,
#                        crate::scene, crate::cpu, crate::export
#   src/cpu/             CPU twins know no device, no screen, no scene:
#                        no crate::gpu, crate::stages, crate::render,
#                        crate::scene, crate::export
#   src/stages/          compute knows no screen and no scene:
#                        no crate::render, crate::scene, crate::export
#   src/scene/planner.rs the plan is data: no crate::gpu, crate::stages,
#                        crate::render
#   src/mesh/, src/volume/  data: no crate::gpu, crate::stages, crate::render,
#                        crate::scene, crate::export
#   src/export/          writers: no crate::gpu, crate::stages, crate::scene
#   src/render/          the screen: no crate::export, crate::scene (the
#                        writers read its frames and cameras, never the reverse);
#                        no crate::stages, crate::gpu (the screen runs no
#                        compute: the caller composes stages and renderer)
#   src/gpu/             the device layer: no crate::cpu, crate::stages,
#                        crate::mesh, crate::volume, crate::render,
#                        crate::export, crate::scene
#   src/output.rs        files written whole: no crate module but error
#   everything below the front door (spec, cpu, gpu, stages, mesh, volume,
#   render, export, scene, api/, error.rs): no crate::report (measurement
#   sits above the front door and calls it; the library knows no tables)
#   window crates        winit, glutin, glutin-winit, egui, egui-winit and
#                        egui_glow only in src/cli/view/ (the viewer), which
#                        uses no shapecue::stages, shapecue::gpu, shapecue::cpu
#   src/cli/ (not view/) the front door only: no shapecue::stages, gpu, cpu,
#   and python/src/      render or scene (shapecue::api names what they need)
#   time in results      no `pub *_ms` or `pub ms` field in src/ outside spec/timing.rs
#                        (Timing), src/report/ and src/cli/
#
# Then an import graph over the same `crate::<module>` paths (python3):
#   - no cycle between the top-level modules of src/, nor between the files
#     (or folders) of any module folder (src/cpu/, src/stages/, ...): a
#     cycle is printed with the file:line of each of its imports;
#   - src/spec/ imports nothing from crate::mesh or crate::volume: data
#     builds on the spec, never the reverse;
#   - src/stages/, src/scene/ and src/api/ import nothing from crate::cpu:
#     the twins are never on the product's path (the front door may
#     re-export a CPU reference with `pub use`).
#   These two read code outside `#[cfg(test)] mod` blocks (a unit test may
#   name another module's items to check that names agree), and resolve
#   `super::`, `self::` and re-exports (`pub use`) to the module that
#   defines an item. `scripts/check-layers.sh --graph` prints the graph.
#
# What counts as a dependency: a `crate::<module>` path anywhere in code
# (`use crate::stages::…`, `crate::render::Renderer` in a signature), and
# `use crate::{<module>…}` groups, also across lines. Comment lines (`//`,
# `///`, `//!`) are skipped, so prose and doc links may name other layers.
set -euo pipefail
cd "$(dirname "$0")/.."

# path (file or folder under src/) | forbidden modules | why
rules=(
    "src/spec|gpu stages render scene cpu export|the spec layer is shared by the CPU twins and the host wiring and imports neither"
    "src/cpu|gpu stages render scene export|CPU twins and spec know no device"
    "src/gpu|cpu stages mesh volume render export scene|the device layer knows no stage family, data or screen"
    "src/stages|render scene export|compute knows no screen"
    "src/scene/planner.rs|gpu stages render|the plan is data, free of the device layer"
    "src/mesh|gpu stages render scene export|data knows no device and no screen"
    "src/volume|gpu stages render scene export|data knows no device and no screen"
    "src/render|export scene|the screen draws; the writers read its frames and cameras, never the reverse"
    "src/render|stages gpu|the screen runs no compute: the caller composes stages and renderer"
    "src/export|gpu stages scene|writers know no device (they may read the renderer's frames and cameras)"
    "src/output.rs|api cpu export gpu mesh metrics render scene spec stages volume report|files written whole or not at all: below every layer that writes"
    "src/spec|report|measurement sits above the front door: the library knows no tables"
    "src/cpu|report|measurement sits above the front door: the library knows no tables"
    "src/gpu|report|measurement sits above the front door: the library knows no tables"
    "src/stages|report|measurement sits above the front door: the library knows no tables"
    "src/mesh|report|measurement sits above the front door: the library knows no tables"
    "src/volume|report|measurement sits above the front door: the library knows no tables"
    "src/render|report|measurement sits above the front door: the library knows no tables"
    "src/export|report|measurement sits above the front door: the library knows no tables"
    "src/scene|report|measurement sits above the front door: the library knows no tables"
    "src/api|report|measurement sits above the front door: the library knows no tables"
    "src/error.rs|report|measurement sits above the front door: the library knows no tables"
)

status=0
for rule in "${rules[@]}"; do
    IFS='|' read -r where forbidden why <<<"$rule"
    [ -e "$where" ] || continue
    while IFS= read -r file; do
        FORBIDDEN="$forbidden" WHY="$why" WHERE="$where" perl -ne '
            BEGIN {
                %bad = map { $_ => 1 } split " ", $ENV{FORBIDDEN};
                $re = join "|", sort keys %bad;
            }
            # A `use crate::{…}` group that spans lines: collect it whole.
            if (defined $group) {
                $group .= $_;
                if (($group =~ tr/{//) == ($group =~ tr/}//)) {
                    check_group($group, $group_line);
                    undef $group;
                }
                next;
            }
            next if m{^\s*//};
            # Direct paths: crate::stages::…, crate::render (also in `use`).
            while (m{\bcrate::($re)\b}g) {
                report($., $1);
            }
            if (m{\buse\s+crate::\{}) {
                my $rest = substr($_, $-[0]);
                if (($rest =~ tr/{//) == ($rest =~ tr/}//)) {
                    check_group($rest, $.);
                } else {
                    ($group, $group_line) = ($rest, $.);
                }
            }
            sub check_group {
                my ($text, $line) = @_;
                $text =~ s{//[^\n]*}{}g;
                $text =~ s{^.*?crate::\{}{}s;
                # The top-level names of the group: strip nested groups first.
                1 while $text =~ s/\{[^{}]*\}//g;
                for my $item (split /,/, $text) {
                    my ($name) = $item =~ m{^\s*(\w+)};
                    report($line, $name) if defined $name && $bad{$name};
                }
            }
            sub report {
                my ($line, $module) = @_;
                print "$ARGV:$line: $ENV{WHERE} must not use crate::$module ($ENV{WHY})\n";
                $found = 1;
            }
            END { exit($found ? 1 : 0) }
        ' "$file" || status=1
    done < <(find "$where" -name '*.rs' | sort)
done

python3 - "$@" <<'PY' || status=1
# The import graph of src/: which module uses which, through `crate::`,
# `super::` and `self::` paths and `use` trees, outside `#[cfg(test)]` mods.
import os, re, sys
from collections import defaultdict

def strip(src):
    """The code without comments, string and char literals emptied; lines kept."""
    out, i, n = [], 0, len(src)
    raw, char = re.compile(r'b?r(#*)"'), re.compile(r"'(\\.[^']*|[^'\\])'")
    while i < n:
        c = src[i]
        m = raw.match(src, i) if c in 'br' and not (src[i - 1:i].isalnum() or src[i - 1:i] == '_') else None
        if src.startswith('//', i):
            j = src.find('\n', i)
            i = n if j < 0 else j
        elif src.startswith('/*', i):
            depth, i = 1, i + 2
            while i < n and depth:
                if src.startswith('/*', i): depth, i = depth + 1, i + 2
                elif src.startswith('*/', i): depth, i = depth - 1, i + 2
                else: out.append('\n' if src[i] == '\n' else ''); i += 1
        elif m:
            end = src.find('"' + m.group(1), m.end())
            end = n if end < 0 else end + 1 + len(m.group(1))
            out.append('""' + '\n' * src.count('\n', i, end)); i = end
        elif c == '"':
            j = i + 1
            while j < n and src[j] != '"':
                j += 2 if src[j] == '\\' else 1
            out.append('""' + '\n' * src.count('\n', i, j)); i = j + 1
        elif c == "'" and (m := char.match(src, i)):
            out.append("' '"); i = m.end()
        else:
            out.append(c); i += 1
    return ''.join(out)

def split(s):
    return [p for p in s.split('::') if p]

def expand(tree):
    """`a::{b, c::{d, e as f}, g::*}` -> [a, b], [a, c, d], [a, c, e], [a, g]."""
    s = re.sub(r'\s+', '', re.sub(r'\s+as\s+\w+', '', tree))
    def group(pos):  # s[pos] follows a '{'
        res = []
        while pos < len(s) and s[pos] != '}':
            head = ''
            while pos < len(s) and s[pos] not in '{},':
                head, pos = head + s[pos], pos + 1
            if pos < len(s) and s[pos] == '{':
                inner, pos = group(pos + 1)
                res += [split(head) + p for p in inner]
            else:
                res.append(split(head))
            pos += pos < len(s) and s[pos] == ','
        return res, pos + 1
    k = s.find('{')
    res = [split(s[:k]) + p for p in group(k + 1)[0]] if k >= 0 else [split(s)]
    return [q for q in ([x for x in p if x not in ('*', 'self')] for p in res) if q]

def blocks(text, pattern):
    """(start, end, name) of each `mod name {…}` that `pattern` finds."""
    spans = []
    for m in re.finditer(pattern, text):
        depth, j = 1, m.end()
        while j < len(text) and depth:
            depth += {'{': 1, '}': -1}.get(text[j], 0); j += 1
        spans.append((m.start(), j, m.group('name')))
    return spans

files = sorted(os.path.join(d, f) for d, _, fs in os.walk('src') for f in fs if f.endswith('.rs'))
where, code, children = {}, {}, defaultdict(set)
for f in files:
    rel = os.path.relpath(f, 'src')[:-3].split(os.sep)
    rel = [] if rel in (['lib'], ['main']) else rel[:-1] if rel[-1] == 'mod' else rel
    where[f] = ('bin' if f == 'src/main.rs' or rel[:1] == ['cli'] else 'lib', tuple(rel))
    code[f] = strip(open(f, encoding='utf-8').read())
    children[where[f]] |= set(re.findall(r'\bmod\s+(\w+)\s*;', code[f]))

uses, reexports = defaultdict(list), defaultdict(dict)
for f in files:
    crate, mod = where[f]
    text = code[f]
    inline = blocks(text, r'\bmod\s+(?P<name>\w+)\s*\{')
    tests = blocks(text, r'#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+(?P<name>\w+)\s*\{')
    def absolute(path, pos):
        inner = tuple(name for a, b, name in inline if a < pos < b)
        here = mod + inner
        if path[0] == 'crate':
            return tuple(path[1:])
        if path[0] in ('super', 'self'):
            while path and path[0] in ('super', 'self'):
                here, path = (here[:-1] if path[0] == 'super' else here), path[1:]
            return here + tuple(path)
        if not inner and path[0] in children[(crate, mod)]:
            return mod + tuple(path)
        return None  # another crate, or a name already in scope
    skip = [(a, b) for a, b, _ in tests]
    for m in re.finditer(r'(\bpub(?:\([^)]*\))?\s+)?\buse\s+([^;]+);', text):
        skip.append((m.start(), m.end()))
        if any(a <= m.start() < b for a, b, _ in tests):
            continue
        for p in expand(m.group(2)):
            if (a := absolute(p, m.start())) is not None:
                uses[f].append((text.count('\n', 0, m.start()) + 1, a))
                if m.group(1) and not any(x < m.start() < y for x, y, _ in inline):
                    reexports[(crate, mod)][p[-1]] = a
    for m in re.finditer(r'\b(?:crate|super|self)(?:\s*::\s*\w+)+', text):
        if not any(a <= m.start() < b for a, b in skip):
            if a := absolute(split(re.sub(r'\s+', '', m.group(0))), m.start()):
                uses[f].append((text.count('\n', 0, m.start()) + 1, a))

def child_of(crate, parent, path, hops=0):
    """The child module of `parent` that defines what `path` names."""
    if path[:len(parent)] != parent or len(path) <= len(parent) or hops > 8:
        return None
    c = path[len(parent)]
    if c in children[(crate, parent)]:
        return c
    to = reexports[(crate, parent)].get(c)
    return child_of(crate, parent, to + path[len(parent) + 1:], hops + 1) if to else None

def graph(crate, parent):
    edges = defaultdict(lambda: defaultdict(list))
    for f in files:
        c, mod = where[f]
        if c == crate and mod[:len(parent)] == parent and len(mod) > len(parent):
            for line, a in uses[f]:
                dst = child_of(crate, parent, a)
                if dst and dst != mod[len(parent)]:
                    at = edges[mod[len(parent)]][dst]
                    at += [] if f'{f}:{line}' in at else [f'{f}:{line}']
    return edges

def cycles(edges):
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    def visit(v):
        index[v] = low[v] = len(index); stack.append(v); on.add(v)
        for w in sorted(edges[v]):
            if w not in index: visit(w); low[v] = min(low[v], low[w])
            elif w in on: low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while not comp or comp[-1] != v:
                comp.append(stack.pop()); on.discard(comp[-1])
            if len(comp) > 1: out.append(sorted(comp))
    for v in sorted(list(edges)):
        if v not in index: visit(v)
    return out

found = False
for crate, parent in sorted({(c, m[:k]) for c, m in where.values() for k in range(len(m))}):
    edges = graph(crate, parent)
    name = 'src/' + '/'.join(parent) if parent else ('src/ (its top-level modules)' if crate == 'lib' else 'src/main.rs')
    if '--graph' in sys.argv:
        for a in sorted(edges):
            print(f"{name}: {a} -> {' '.join(sorted(edges[a]))}")
    for comp in cycles(edges):
        found = True
        print(f"{name}: module cycle {' <-> '.join(comp)} (no cycles between the modules under src/)")
        for a in comp:
            for b in comp:
                if b in edges[a]:
                    print(f"  {a} -> {b}: {', '.join(edges[a][b][:5])}")
    if crate == 'lib' and not parent:
        for dst in ('mesh', 'volume'):
            for at in edges['spec'].get(dst, []):
                found = True
                print(f"{at}: src/spec must not use crate::{dst} (data builds on the spec, never the reverse)")
# The twins stay off the product's path: nothing under src/stages,
# src/scene or src/api uses crate::cpu outside its unit tests, but the
# front door's re-exports of a CPU reference (`pub use` in src/api, offered
# to callers beside the device's call, never called by the library).
for f in files:
    crate, mod = where[f]
    if crate != 'lib' or mod[:1] not in (('stages',), ('scene',), ('api',)):
        continue
    text = code[f]
    pub_uses = [(text.count('\n', 0, m.start()) + 1)
                for m in re.finditer(r'\bpub\s+use\s+crate::cpu::', text)]
    for line, a in uses[f]:
        if a[:1] == ('cpu',) and not (mod[:1] == ('api',) and line in pub_uses):
            found = True
            print(f"{f}:{line}: {'/'.join(('src',) + mod[:1])} must not use crate::{'::'.join(a)} "
                  "(src/cpu holds the twins and references; a host step of the product is a stage, "
                  "and what both sides need is in src/spec)")
sys.exit(1 if found else 0)
PY

# The scene executor holds its state in one value per lifetime (run,
# topology, pose, view: src/scene/exec/passes/state.rs), not a field per
# quantity: at most 15 fields.
exec_fields=$(awk '/^pub\(super\) struct Executor/ {on = 1; next} on && /^}/ {on = 0}
    on && /^    [a-z_]+(\([a-z]+\))? ?[a-z_]*:/ && !/^    \/\// {n++} END {print n + 0}' src/scene/exec/passes/mod.rs)
if [ "$exec_fields" -gt 15 ] || [ "$exec_fields" -eq 0 ]; then
    echo "src/scene/exec/passes/mod.rs: the executor has $exec_fields fields, more than 15 (or none found): group new state by lifetime in passes/state.rs"
    status=1
fi

# The command-line parser belongs to the binary: the library's option enums
# implement spec::Choice, from which src/cli builds clap's parsers.
while IFS= read -r hit; do
    echo "$hit: clap outside src/cli and src/main.rs (the library knows no command-line parser)"
    status=1
done < <(grep -rn --include='*.rs' -E '\bclap::|use clap\b' src | grep -v -E '^src/(cli/|main\.rs)' | grep -v -E ':[0-9]+:\s*//' || true)

# The window crates belong to the viewer (src/cli/view/), which reaches the
# library through the scene executor, not the stages or the device.
while IFS= read -r hit; do
    echo "$hit: a window crate outside src/cli/view (the library and its renderer know no window)"
    status=1
done < <(grep -rn --include='*.rs' -E '\b(winit|glutin|glutin_winit|egui|egui_winit|egui_glow)::|use (winit|glutin|glutin_winit|egui|egui_winit|egui_glow)\b' src | grep -v -E '^src/cli/view/' | grep -v -E ':[0-9]+:\s*//' || true)
while IFS= read -r hit; do
    echo "$hit: src/cli/view must not use shapecue::stages, shapecue::gpu or shapecue::cpu (the viewer draws through the scene executor)"
    status=1
done < <(grep -rn --include='*.rs' -E '\bshapecue::(stages|gpu|cpu)\b' src/cli/view 2>/dev/null | grep -v -E ':[0-9]+:\s*//' || true)

# The command line reaches the library through the front door (shapecue's
# root and shapecue::api, with report, export, spec and the loaders), never
# the layers below it; the viewer is the one exception (the scene executor).
while IFS= read -r hit; do
    echo "$hit: src/cli (but the viewer) and python/src must not use shapecue::stages, gpu, cpu, render or scene (they go through the front door, shapecue::api)"
    status=1
done < <(grep -rn --include='*.rs' -E '\bshapecue::(stages|gpu|cpu|render|scene)\b' src/cli src/main.rs python/src 2>/dev/null | grep -v -E '^src/cli/view/' | grep -v -E ':[0-9]+:\s*//' || true)

# Time in a library result is one Timing (spec/timing.rs): no other public
# field ending in _ms (or named ms) below the measurement and the command line.
while IFS= read -r hit; do
    echo "$hit: a public *_ms or ms field outside spec::timing::Timing (a library result carries one Timing; repeats and medians live in src/report and src/cli)"
    status=1
done < <(grep -rn --include='*.rs' -E '^\s*pub ([a-z0-9_]*_)?ms\s*:' src | grep -v -E '^src/(spec/timing\.rs|report/|cli/)' || true)

# No source file over 800 lines (ARCHITECTURE.md, "Files over 700 lines").
while IFS= read -r f; do
    n=$(wc -l < "$f")
    if [ "$n" -gt 800 ]; then
        echo "$f: $n lines, over the 800-line limit (split it along its parts)"
        status=1
    fi
done < <(find src kernels tests benches python/src -type f \( -name '*.rs' -o -name '*.cl' -o -name '*.h' \) 2>/dev/null | sort)

if [ "$status" -ne 0 ]; then
    echo "check-layers: the layering or file sizes above are broken; see ARCHITECTURE.md (split a long file along its parts; move the shared type into src/spec/, or the drawing into src/render/; break a cycle by moving the shared piece into the module both use)" >&2
    exit 1
fi
echo "check-layers: ok (each layer imports only what it may; no cycle between modules; no file over 800 lines)"
