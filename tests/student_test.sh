#!/usr/bin/env bash
# What a student trips over: results beyond the small deformation the model assumes, unit slips,
# a tree that cannot be seen, refinement of what the paper plots, --set for studies. Every warning
# fires where it should and stays quiet on every shipped case.
set -uo pipefail
source "$(dirname "$0")/cli_test_env.sh"
fail=0
ok() { echo "ok   $*"; }
bad() { echo "FAIL $*"; fail=1; }
warns() {  # pattern what: the last command's stderr (w.txt) holds a warning matching pattern
  grep -q "^rfem: warning: .*$1" w.txt && ok "$2: $(grep -m1 "$1" w.txt | cut -c1-160)" || bad "$2: $(cat w.txt)"
}

# 1. Validity: the paper's deployment in T = 5 s twists link 3 far beyond small deformation (once:
#    1.24 rad of torsion without a word); the warning is in the file and the JSON too.
"$rfem" run "$src/cases/paper_deployment.toml" --set 'joints.*.input.T=5' --set simulation.t_end=8 --json -o t5.h5 \
  > t5.json 2> w.txt
warns "run force: link 'link': rfe .* turned .* rad relative to {r}" "T = 5 s: validity warning"
/usr/bin/python3 - <<'PY' && ok "the warning is in the file and the JSON" || bad "warning not recorded"
import h5py, json, sys
w = h5py.File("t5.h5")["force"].attrs["warnings"]
j = json.load(open("t5.json"))["runs"][2]["warnings"]
sys.exit(0 if "beyond 0.1 rad" in w and j and "beyond 0.1 rad" in j[0] else 1)
PY
"$rfem" static "$src/cases/kane_beam.toml" --set 'loads.tip_force=[0,0,-50]' > /dev/null 2> w.txt
warns "static equilibrium: link 'link': rfe 40 turned" "a 50 N tip load on Kane's beam"

# 2. Unit slips: A in mm², a payload in grams, a modulus in the wrong unit, an impossible density;
#    values beyond what can be computed are refused (once: modes printed 0 Hz and +inf %).
"$rfem" static "$src/cases/kane_beam.toml" --set sections.kane.A=40 > /dev/null 2> w.txt
warns "sections.kane.A: A = 40 m^2 is a cross-section over a metre across" "A = 40"
"$rfem" show "$src/cases/kane_beam.toml" --set sections.kane.A=4e-3 > /dev/null 2> w.txt
warns "sections.kane.A: A = 0.004 m^2 with Iy + Iz = 4e-07 m^4 is no real section" "A ten times too large for its Iy, Iz"
"$rfem" show "$src/cases/two_link_arm.toml" --set links.1.payloads.0.mass=200 > /dev/null 2> w.txt
warns "links.1.payloads.0.mass: a payload of 200 kg is 463 times the link's mass" "a payload of 200"
refused() {  # pattern what: the last command (exit code $code) stopped with one line matching pattern
  [ $code = 2 ] && [ "$(wc -l < w.txt)" = 1 ] && grep -q "^rfem: error: .*$1" w.txt && ok "$2: $(cut -c1-160 w.txt)" \
    || bad "$2: exit $code $(cat w.txt)"
}
#    A material value beyond any material (once: E = 70 Pa only warned, blaming G, and the run went
#    on to 15 rad) stops the reading unless the case acknowledges it with [case] accept.
"$rfem" static "$src/cases/kane_beam.toml" --set materials.kane.E=7e13 --set materials.kane.G=2.6e11 > /dev/null 2> w.txt; code=$?
refused "materials.kane.E: E = 7e+13 Pa is stiffer than diamond .*accept = \[\"materials.kane.E\"\]" "E = 7e13"
"$rfem" static "$src/cases/kane_beam.toml" --set materials.kane.rho=2.7e5 > /dev/null 2> w.txt; code=$?
refused "materials.kane.rho: rho = 270000 kg/m^3 is denser than any material" "rho = 2.7e5"
"$rfem" run "$src/cases/two_link_arm.toml" --set materials.al.E=70 -q -o e70.h5 > /dev/null 2> w.txt; code=$?
refused "materials.al.E: E = 70 Pa is very small" "E = 70 (Pa for GPa), G sound"
[ ! -e e70.h5 ] && ok "E = 70: nothing run" || bad "E = 70 ran"
"$rfem" show "$src/cases/two_link_arm.toml" --set materials.al.E=70 --set 'case.accept=["materials.al.E"]' > /dev/null 2> w.txt
[ $? = 0 ] && [ ! -s w.txt ] && ok "E = 70 acknowledged: read, and G not blamed" || bad "E = 70 accepted: $(cat w.txt)"
"$rfem" show "$src/cases/two_link_arm.toml" --set materials.al.rho=2.7 > /dev/null 2> w.txt; code=$?
refused "materials.al.rho: rho = 2.7 kg/m^3 is very small" "rho = 2.7 (g/cm^3)"
"$rfem" show "$src/cases/two_link_arm.toml" --set materials.al.rho=2.7 --set 'case.accept=["materials.al.rho"]' > /dev/null 2> w.txt
[ $? = 0 ] && [ ! -s w.txt ] && ok "rho = 2.7 acknowledged: the 0.1 kg payload not taken for grams" || bad "rho = 2.7: $(cat w.txt)"
for v in 1e300 1e-300; do
  "$rfem" modes "$src/cases/kane_beam.toml" --set materials.kane.E=$v > out.txt 2> err.txt; code=$?
  [ $code = 2 ] && grep -q "materials.kane.E: must lie within what rfem computes with" err.txt \
    && ok "E = $v refused: $(cut -c1-120 err.txt)" || bad "E = $v: exit $code $(cat err.txt) $(cat out.txt)"
done

# 3. The tree: `rfem show` prints what sits on what; a joint left without a parent where a link
#    sits on the previous joint draws a warning that says where it went.
"$rfem" show "$src/cases/two_link_arm.toml" > tree.txt 2> w.txt
grep -q "^    joint elbow — on upper, tip (1 m)" tree.txt && grep -q "^      link forearm — on elbow" tree.txt \
  && [ ! -s w.txt ] && ok "show: the elbow on the upper link's tip, the forearm on the elbow" || bad "show: $(cat tree.txt w.txt)"
sed '/^name = "elbow"/{n;d}' "$src/cases/two_link_arm.toml" > noparent.toml
"$rfem" show noparent.toml > tree.txt 2> w.txt
warns "joints.1.parent: missing: joint 'elbow' sits on the previous joint 'shoulder', where link 'upper' sits too" \
  "an elbow without a parent"
"$rfem" show "$src/cases/wrist_payload.toml" --json > tree.json && /usr/bin/python3 -c "
import json, sys
e = {x['name']: x for x in json.load(open('tree.json'))['entries']}
sys.exit(0 if e['wrist']['parent'] == 'beam' and e['beam.payload1']['where'] == 'at 5 m' and e['hub']['depth'] == 0 else 1)" \
  && ok "show --json: wrist on the beam, payload at 5 m" || bad "show --json"

#    A URDF base: a joint the case gives no input is free under zero torque, said once at reading
#    and in the tree (once: silently); a misnamed parent lists the URDF's links (once: "the
#    mountings form a cycle"); a [[joints]] path on URDF joints points to base.joints.NAME.
sed -e '/^\[base.joints.elbow\]/,/^$/d' -e 's#"urdf/#"'"$src"'/cases/urdf/#' "$src/cases/urdf_arm.toml" > noelbow.toml
"$rfem" show noelbow.toml > tree.txt 2> w.txt
warns "base.joints: URDF joint 'elbow' has no input: free, under zero torque" "a URDF joint without an input"
[ "$(grep -c . w.txt)" = 1 ] && grep -q "joint elbow — on shoulder: revolute about y; input none given: free, under zero torque" tree.txt \
  && ok "show: the elbow free, said once" || bad "show, free elbow: $(cat w.txt tree.txt)"
"$rfem" show "$src/cases/urdf_arm.toml" --set link.name=link --set link.parent=link > /dev/null 2> w.txt; code=$?
refused "link.parent: 'link' is this link itself: no other joint or link has that name (joints elbow, shoulder, waist; URDF links base_link, forearm, tool0, turret, upper_arm; or \"ground\")" \
  "a URDF link misnamed as the link itself"
"$rfem" run "$src/cases/urdf_arm.toml" --set joints.1.input.kp=5 > /dev/null 2> w.txt; code=$?
refused "joints: this case's joints come from its URDF (waist, shoulder, elbow): .*(joints.1.input.kp is base.joints.shoulder.input.kp)" \
  "joints.1.input.kp on URDF joints"

# 4. Refinement of what the paper plots: the torque the flexibility adds (Fig. 6's point), its RMS
#    over the motion, the force run's rate; only the runs the quantities read are run.
"$rfem" --threads 1 refine "$src/cases/paper_deployment.toml" --n 12,24,48 --no-integration-check \
  --quantity 'peak:kinematic/tau3-rigid/tau3,rms:kinematic/tau3-rigid/tau3[0:15]' -q -o ripple.h5 > ripple.txt 2> w.txt
/usr/bin/python3 - <<'PY' && ok "ripple refined from the rigid and kinematic runs only: $(grep -m1 ' 48 ' ripple.txt)" || bad "ripple: $(cat ripple.txt w.txt)"
import h5py, numpy as np, sys
f = h5py.File("ripple.h5")
runs = sorted(f["n12"])
# The quantity is the largest |τ3 flexible − τ3 rigid| of those runs' own series.
d = np.abs(f["n48/kinematic/joint_tau"][:, 2] - f["n48/rigid/joint_tau"][:, 2]).max()
v = f["refine/q0/value"][-1]
sys.exit(0 if runs == ["kinematic", "rigid"] and abs(v - d) <= 1e-12 * d else 1)
PY
"$rfem" refine "$src/cases/paper_deployment.toml" --n 6,12 --quantity 'rms:tau3[5:1]' 2> err.txt; code=$?
[ $code = 2 ] && grep -q "the window must lie in the run" err.txt && ok "a window backwards: $(cat err.txt)" || bad "window: $(cat err.txt)"

# 5. --set for studies: a wildcard over arrays; keys of the other link layout answered with the
#    keys that work (once: an error that blamed the file).
"$rfem" run "$src/cases/paper_deployment.toml" --set 'joints.*.input.T=10' --set simulation.t_end=0.2 \
  --set simulation.procedure=\"single\" -q -o star.h5 && /usr/bin/python3 -c "
import h5py, sys
sys.exit(0 if 'T = 10' in h5py.File('star.h5').attrs['case_effective'].replace('T = 10.0', 'T = 10') and 'T = 15' not in h5py.File('star.h5').attrs['case_effective'] else 1)" \
  && ok "joints.*.input.T=10 sets every joint" || bad "wildcard"
"$rfem" run "$src/cases/two_link_arm.toml" --set link.n=40 2> err.txt; code=$?
[ $code = 2 ] && grep -q -- "--set link.n: this case has several links (\[\[links\]\]): use links.0.n, links.\*.n, or --n N" err.txt \
  && ok "link.n on two links: $(cut -c1-140 err.txt)" || bad "link.n: $(cat err.txt)"

# 6. Quiet on every shipped case: no warning from reading, showing, statics (links) or a short run.
for c in "$src"/cases/*.toml; do
  name=$(basename "$c")
  "$rfem" show "$c" > /dev/null 2> w.txt
  if grep -q "^\[link\]\|^\[\[links\]\]" "$c"; then "$rfem" static "$c" > /dev/null 2>> w.txt; fi
  if grep -q "^\[simulation\]" "$c"; then "$rfem" run "$c" --set simulation.t_end=0.5 -q -o quiet.h5 2>> w.txt; fi
  [ -s w.txt ] && bad "$name is not quiet: $(cat w.txt)"
done
[ $fail = 0 ] && ok "every shipped case reads, shows, stands and runs without a warning"

[ $fail = 0 ] && echo "all passed" || echo "failures above"
exit $fail
