#!/usr/bin/env bash
# Checks the layering of src/ (ARCHITECTURE.md): the dependencies that must
# never exist. Run by .ci/run before the build; run it yourself after moving
# code. Prints every offending file:line with the rule it breaks and exits 1,
# or prints one line and exits 0.
#
#   src/spec/            knows no device, no screen, no scene and no CPU twin:
#                        no crate::gpu, crate::stages, crate::render,
#                        crate::scene, crate::cpu
#   src/cpu/             CPU twins know no device, no screen, no scene:
#                        no crate::gpu, crate::stages, crate::render, crate::scene
#   src/stages/          compute knows no screen and no scene:
#                        no crate::render, crate::scene
#   src/scene/planner.rs the plan is data: no crate::gpu, crate::stages,
#                        crate::render
#   src/mesh/, src/volume/  data: no crate::gpu, crate::stages, crate::render,
#                        crate::scene
#   src/export/          writers: no crate::gpu, crate::stages, crate::scene
#   everything below the front door (spec, cpu, gpu, stages, mesh, volume,
#   render, export, scene, api.rs, error.rs): no crate::report (measurement
#   sits above the front door and calls it; the library knows no tables)
#
# What counts as a dependency: a `crate::<module>` path anywhere in code
# (`use crate::stages::…`, `crate::render::Renderer` in a signature), and
# `use crate::{<module>…}` groups, also across lines. Comment lines (`//`,
# `///`, `//!`) are skipped, so prose and doc links may name other layers.
set -euo pipefail
cd "$(dirname "$0")/.."

# path (file or folder under src/) | forbidden modules | why
rules=(
    "src/spec|gpu stages render scene cpu|the spec layer is shared by the CPU twins and the host wiring and imports neither"
    "src/cpu|gpu stages render scene|CPU twins and spec know no device"
    "src/stages|render scene|compute knows no screen"
    "src/scene/planner.rs|gpu stages render|the plan is data, free of the device layer"
    "src/mesh|gpu stages render scene|data knows no device and no screen"
    "src/volume|gpu stages render scene|data knows no device and no screen"
    "src/export|gpu stages scene|writers know no device (they may read the renderer's frames and cameras)"
    "src/spec|report|measurement sits above the front door: the library knows no tables"
    "src/cpu|report|measurement sits above the front door: the library knows no tables"
    "src/gpu|report|measurement sits above the front door: the library knows no tables"
    "src/stages|report|measurement sits above the front door: the library knows no tables"
    "src/mesh|report|measurement sits above the front door: the library knows no tables"
    "src/volume|report|measurement sits above the front door: the library knows no tables"
    "src/render|report|measurement sits above the front door: the library knows no tables"
    "src/export|report|measurement sits above the front door: the library knows no tables"
    "src/scene|report|measurement sits above the front door: the library knows no tables"
    "src/api.rs|report|measurement sits above the front door: the library knows no tables"
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

if [ "$status" -ne 0 ]; then
    echo "check-layers: the layering above is broken; see ARCHITECTURE.md (move the shared type into src/spec/, or the drawing into src/render/)" >&2
    exit 1
fi
echo "check-layers: ok (spec, cpu twins, stages, the planner, data and writers import only what their layer may)"
