#!/bin/sh
# `craneassist research follow` with broken inputs (docs/mobile.md): a tool-path file that breaks the
# text rules, a path the platform cannot follow (a cusp of its offset path, a turn tighter than
# the steering allows), a broken base config, a missing file: exit code 2 and one message naming
# file, line and field.
# Usage: follow_bad_input.sh CRANEASSIST SOURCE_DIR WORKDIR
set -u
bin=$1 src=$2 work=$3
mkdir -p "$work"
. "$(dirname "$0")/expect_lib.sh"
printf '# a typo\nx,y\n0,0\n8,0.O\n' > "$work/typo.csv"
expect typo "tool path: $work/typo.csv:4: field 'y': not a number: '0.O'" research follow "$work/typo.csv" --no-log
printf 'x,y,z\n0,0,1\n8,0,1\n' > "$work/header.csv"
expect header "tool path: $work/header.csv:1: expected the header 'x,y', got 'x,y,z'" research follow "$work/header.csv" --no-log
printf 'x,y\n0,0\n' > "$work/one.csv"
expect one_point "tool path: $work/one.csv:2: a tool path needs at least 2 via points, got 1" research follow "$work/one.csv" --no-log
printf 'x,y\n0,0\n0.001,0\n' > "$work/close.csv"
expect close "tool path: $work/close.csv:3: via point 0.001 m from the one before (line 2); at least 0.01 m apart" research follow "$work/close.csv" --no-log
printf 'x,y\n0,0\n6,0\n9,-3\n10,-8\n' > "$work/cusp.csv"
expect cusp "tool path: $work/cusp.csv:3: the platform's path, 4.5 m beside the tool path (path_following.tool_offset), has a cusp here" research follow "$work/cusp.csv" --no-log
printf 'x,y\n0,0\n6,0\n10,-2\n12,-6\n' > "$work/tight.csv"
expect tight "tool path: $work/tight.csv:4: the platform's path turns on a radius of 0.803 m here, tighter than the steering allows (2.39 m at the chassis centre)" research follow "$work/tight.csv" --no-log
expect missing "tool path: $work/none.csv: file not found" research follow "$work/none.csv" --no-log
base=$src/config/machines/mobile_base.yaml
line=$(grep -n 'gear_ratio: 17.7, paper' "$base" | cut -d: -f1)
sed 's/gear_ratio: 17.7, paper/gear_ratio: 17.7/' "$base" > "$work/base.yaml"
expect base_source "config: $work/base.yaml:$line: field 'drive.gear_ratio': missing source" \
  research follow "$src/examples/paths/mobile_s_curve.csv" --base "$work/base.yaml" --no-log
line=$(grep -n 'steer_max: 45 deg, paper' "$base" | cut -d: -f1)
sed 's/steer_max: 45 deg, paper/steer_max: 45 m, paper/' "$base" > "$work/base_unit.yaml"
expect base_unit "config: $work/base_unit.yaml:$line: field 'chassis.steer_max': unit 'm' is not a angle unit" \
  research follow "$src/examples/paths/mobile_s_curve.csv" --base "$work/base_unit.yaml" --no-log
expect nan_option "--height-amplitude" research follow "$src/examples/paths/mobile_s_curve.csv" --height-amplitude nan --no-log
expect pump_value "--pump" research follow "$src/examples/paths/mobile_s_curve.csv" --pump both --no-log
line=$(grep -n 'shared_with_crane: false' "$base" | cut -d: -f1)
sed 's/shared_with_crane: false/shared_with_crane: sometimes/' "$base" > "$work/base_shared.yaml"
expect base_shared "config: $work/base_shared.yaml:$line: field 'drive.shared_with_crane'" \
  research follow "$src/examples/paths/mobile_s_curve.csv" --base "$work/base_shared.yaml" --no-log
[ "$failed" -eq 0 ] && echo "follow bad input OK"
exit $failed
