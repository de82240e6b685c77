#!/bin/sh
# A broken input file of each format (replay, tip path, joint trajectory, the YAML files), through
# every command that reads it, a file over the size limit of each format, and option values no
# check may let through (NaN): exit code 2 and one message naming format, file, line and field,
# or the option.
# Usage: bad_input_files.sh CRANEASSIST DATA_DIR WORKDIR
set -u
bin=$1 data=$2 work=$3
mkdir -p "$work"
. "$(dirname "$0")/expect_lib.sh"
demo=$data/../../examples/replays/demo.csv
replay="replay: $data/bad_replay.csv:4: field 'v_y': not a number: '0.1x'"
path="path: $data/bad_path.csv:4: field 'y': not a number: '2.O4'"
trajectory="trajectory: $data/bad_trajectory.csv:3: field 'qdot_2': not a number: 'abc'"
expect replay "$replay" replay "$data/bad_replay.csv" --no-log
expect sim_replay "$replay" sim --input replay "$data/bad_replay.csv" --no-realtime
expect bound_replay "$replay" research bound "$data/bad_replay.csv"
expect plan_path "$path" research plan "$data/bad_path.csv" --quiet --out "$work/plan.csv"
expect bound_path "$path" research bound "$data/bad_path.csv"
expect trajectory "$trajectory" replay --trajectory "$data/bad_trajectory.csv" --no-log
# A plan's positions must lie in the crane's joint ranges (the K70M's lift ends at 1.097 rad).
printf 't,q_1,q_2,q_3,q_4,qdot_1,qdot_2,qdot_3,qdot_4,qddot_1,qddot_2,qddot_3,qddot_4\n%s\n%s\n' \
  0,0,0.3,-1.2,0.5,0,0,0,0,0,0,0,0 1,0,1.2,-1.2,0.5,0,0,0,0,0,0,0,0 > "$work/far_lift.csv"
expect trajectory_range "trajectory: $work/far_lift.csv:3: field 'q_2': 1.2 rad is outside the range of joint 'lift', [-0.425, 1.097] rad" \
  replay --trajectory "$work/far_lift.csv" --no-log
# A CAN mapping that is broken or does not fit the crane is an input error (exit 2), found
# before a bus is opened (this host may have no CAN at all: the bus would fail with exit 3).
mapping=$data/../../config/can/k70m_can.yaml
printf 'format: craneassist-can-map/1\njoints: 3\n' > "$work/bad_map.yaml"
bad_map="config: $work/bad_map.yaml:2: field 'joints': expected a list of joints"
expect can_bad_mapping "$bad_map" replay --backend can --can vcan0 --mapping "$work/bad_map.yaml" --no-log
expect emulate_bad_mapping "$bad_map" emulate --can vcan0 --mapping "$work/bad_map.yaml"
line=$(grep -n 'unit: deg, min: -90, max: 90}' "$mapping" | cut -d: -f1)
sed 's/unit: deg, min: -90, max: 90}/unit: deg, min: -10, max: 90}/' "$mapping" > "$work/narrow_map.yaml"
narrow="config: $work/narrow_map.yaml:$((line - 1)): field 'joints[1].position': joint 'lift': the position signal's min/max do not cover the joint range"
expect can_narrow_mapping "$narrow" replay --backend can --can vcan0 --mapping "$work/narrow_map.yaml" --no-log
expect sim_narrow_mapping "$narrow" sim --backend can --can vcan0 --mapping "$work/narrow_map.yaml" \
  --input replay "$demo"
expect emulate_narrow_mapping "$narrow" emulate --can vcan0 --mapping "$work/narrow_map.yaml"
expect calibrate_narrow_mapping "$narrow" calibrate --backend can --can vcan0 \
  --mapping "$work/narrow_map.yaml" --out "$work/tables.yaml" --log "$work/sweep.csv"
# Every file is read with its format's size bound (YAML 1 MiB, CSV 64 MiB): a file without an
# end (/dev/zero) and a larger regular file (sparse, nothing written) are refused, not read
# until the memory runs out.
limit() { echo "$1: larger than $2 MiB (the limit for $3 files)"; }
expect zero_replay "replay: $(limit /dev/zero 64 replay)" replay /dev/zero --no-log
expect zero_config "config: $(limit /dev/zero 1 'crane config')" replay --config /dev/zero --no-log
expect zero_trajectory "trajectory: $(limit /dev/zero 64 'joint trajectory')" \
  replay --trajectory /dev/zero --no-log
expect zero_telemetry "config: $(limit /dev/zero 1 'telemetry config')" \
  replay --telemetry-config /dev/zero --no-log
expect zero_plan "path: $(limit /dev/zero 64 'tip path')" research plan /dev/zero --quiet --out "$work/plan.csv"
expect zero_bound "replay: $(limit /dev/zero 64 'tip path and replay')" research bound /dev/zero
expect zero_sim "replay: $(limit /dev/zero 64 replay)" sim --input replay /dev/zero --no-realtime
expect zero_joystick "config: $(limit /dev/zero 1 'joystick mapping')" \
  sim --input replay "$demo" --no-realtime --joystick /dev/zero
expect zero_mapping "config: $(limit /dev/zero 1 'CAN mapping')" \
  replay --backend can --can vcan0 --mapping /dev/zero --no-log
expect zero_suite "$(limit /dev/zero 1 'suite manifest')" suite /dev/zero
rm -f "$work/big.csv" "$work/big.yaml"
truncate -s $((64 * 1024 * 1024 + 1)) "$work/big.csv"
truncate -s $((1024 * 1024 + 1)) "$work/big.yaml"
expect big_replay "replay: $(limit "$work/big.csv" 64 replay)" replay "$work/big.csv" --no-log
expect big_config "config: $(limit "$work/big.yaml" 1 'crane config')" \
  replay --config "$work/big.yaml" --no-log
rm -f "$work/big.csv" "$work/big.yaml"
# A key given twice in one mapping is an error at the second (YAML readers would take the first).
crane=$data/../../config/cranes/k70m.yaml
first=$(grep -n '^  rate: 100 Hz' "$crane" | cut -d: -f1)
sed "${first}a\\  rate: 7 Hz, assumed" "$crane" > "$work/duplicate.yaml"
expect duplicate_key "config: $work/duplicate.yaml:$((first + 1)): field 'control.rate': duplicate key (first at line $first)" \
  replay --config "$work/duplicate.yaml" --no-log
# A crane the simulator cannot take is refused before it runs (it ran: gravity -1000 m/s^2 with
# 170 deg of direction error, exit 0; a 1e30 m link aborted in ODE, exit 134).
line=$(grep -n 'gravity: 0 0 -9.81' "$crane" | cut -d: -f1)
sed 's|gravity: 0 0 -9.81 m/s^2|gravity: 0 0 -1000 m/s^2|' "$crane" > "$work/gravity.yaml"
expect gravity "config: $work/gravity.yaml:$line: field 'frames.gravity': magnitude 1000 m/s^2 must be at most 20 m/s^2" \
  replay --config "$work/gravity.yaml" --no-log
line=$(grep -n '    a: 3.504 m' "$crane" | cut -d: -f1)
sed 's|    a: 3.504 m|    a: 1e30 m|' "$crane" > "$work/long_link.yaml"
expect long_link "config: $work/long_link.yaml:$line: field 'joints[1].a': must be within +-100 m" \
  replay --config "$work/long_link.yaml" --no-log
# A floating-point option given NaN or an infinity is refused naming the option (CLI11's Range
# lets NaN through: every comparison with it is false).
expect nan_settle "--settle: 'nan' is not a finite number in [0, 600]" replay --settle nan --no-log
expect nan_feedback_timeout "--can-feedback-timeout: 'nan' is not a finite number" \
  replay --can-feedback-timeout nan --no-log
expect nan_payload "--payload: 'nan' is not a finite number" replay --payload nan --no-log
expect inf_duration "--duration: 'inf' is not a finite number" \
  sim --input replay "$demo" --no-realtime --duration inf
expect nan_dt "--dt: 'nan' is not a finite number" research plan "$data/../../examples/paths/vertical.csv" --dt nan
expect nan_ds "--ds: 'nan' is not a finite number" research bound "$data/../../examples/paths/vertical.csv" --ds nan
expect nan_emulate "--feedback-period: 'nan' is not a finite number" \
  emulate --can vcan0 --feedback-period nan
expect nan_speed "--speed: '-nan' is not a finite number" research experiment-2r --speed -nan
# A command-line override of a config field goes through that field's range check (it skipped
# it: --pump-max-flow "1e30 L/min" ran).
expect big_flow "--pump-max-flow: must be positive and at most 60000 L/min" \
  replay --pump-max-flow "1e30 L/min" --no-log
expect big_power "--prime-mover-power: must be between 1 W and 10000 kW" \
  replay --prime-mover-power "1e30 W" --no-log
expect negative_supply "--supply-pressure: must be positive and at most max_pressure" \
  replay --pump-mode cp --supply-pressure -5 --no-log
expect big_payload "--payload: must be between 0 and 100000 kg" replay --payload 1e6 --no-log
expect big_feedback_timeout "--can-feedback-timeout: must be between 1 ms and 1 s" \
  replay --can-feedback-timeout 30 --no-log
expect calibrate_feedback_timeout "--can-feedback-timeout: must be between 1 ms and 1 s" \
  calibrate --backend can --can vcan0 --can-feedback-timeout 30
expect calibrate_nan_level "--levels: 'nan' is not a finite number" calibrate --levels 0.5,nan
expect calibrate_zero_level "--levels: each level must be in (0, 1], got 0" calibrate --levels 0,1
expect calibrate_level_order "--levels: the levels must be strictly ascending" \
  calibrate --levels 0.6,0.3
# craneassist research ptp (docs/mhsb.md#the-planner): bad points and weights, a point outside the
# workspace, an option the crane cannot take; all found before a posture table is built.
arm=$data/../../config/cranes/mhsb_3link.yaml
nt=$work/no-table.bin
expect ptp_bad_point "--from: '0.55': expected two numbers X,Z (m)" \
  research ptp --config "$arm" --table "$nt" --from 0.55 --to 0.5,0
expect ptp_nan_point "--to: 'nan,0': expected two numbers X,Z (m)" \
  research ptp --config "$arm" --table "$nt" --from 0.5,0 --to nan,0
expect ptp_outside "--to: (3.000, 0.000) m is outside the workspace of MHSB three-link arm (paper 001)" \
  research ptp --config "$arm" --table "$nt" --from 0.55,-0.05 --to 3,0
expect ptp_bad_weights "--weights: '1,x,2': expected three numbers w1,w2,w3" \
  research ptp --config "$arm" --table "$nt" --from 0.5,0 --to 0.6,0 --weights 1,x,2
expect ptp_negative_weight "--weights: '1,-1,2': negative" \
  research ptp --config "$arm" --table "$nt" --from 0.5,0 --to 0.6,0 --weights 1,-1,2
expect ptp_no_circuit "--energy-model: K70M forestry loader (reference crane) has no MHSB circuit" \
  research ptp --table "$nt" --from 4,1 --to 7,4 --energy-model paper
expect ptp_bad_velocity "--velocity-limit: unit 'bar' is not a velocity unit" \
  research ptp --config "$arm" --table "$nt" --from 0.5,0 --to 0.6,0 --velocity-limit "3 bar"
expect ptp_bad_grid "--grid: must be between 5 mm and 5 m" \
  research ptp --config "$arm" --table "$nt" --from 0.5,0 --to 0.6,0 --grid "1 mm"
expect ptp_grid_too_fine "--grid: 10 mm gives up to 2.3e+06 grid cells for K70M forestry loader (reference crane) (reach 7.58 m): its table would take hours; at most 1e+06 cells, 16 mm or coarser" \
  research ptp --table "$nt" --from 4,1 --to 7,4 --grid "1 cm"
expect sim_goal_grid_too_fine "--goal-grid: 5 mm gives up to 9.19e+06 grid cells" \
  sim --input goal --goal 5,1 --goal-grid "5 mm" --no-telemetry
expect ptp_bad_continuity "--continuity-tolerance: '2' is not a finite number in [0, 0.99]" \
  research ptp --config "$arm" --table "$nt" --from 0.5,0 --to 0.6,0 --continuity-tolerance 2
expect ptp_bad_posture "--posture: 'fixed-j3': expected optimal or fixed-last:ANGLE" \
  research ptp --config "$arm" --table "$nt" --from 0.5,0 --to 0.6,0 --posture fixed-j3
expect ptp_posture_nan "--posture: 'abc' is not a finite number" \
  research ptp --config "$arm" --table "$nt" --from 0.5,0 --to 0.6,0 --posture fixed-last:abc
expect ptp_posture_range "--posture: MHSB three-link arm (paper 001): 140.0 deg is outside J3's range" \
  research ptp --config "$arm" --from 0.5,0 --to 0.6,0 --posture fixed-last:140
expect ptp_posture_prismatic "--posture: K70M forestry loader (reference crane): the last moving joint (extension) is not revolute" \
  research ptp --from 4,1 --to 7,4 --posture fixed-last:10
[ "$failed" -eq 0 ] && echo "bad input files OK"
exit "$failed"
