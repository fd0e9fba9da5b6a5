#!/usr/bin/env bash
# Several flexible links from the command line: per-link summaries, JSON and HDF5
# datasets (the top-level ones soft links to the last link's), the elbow joint riding on the upper
# link's tip, tip loads on a chosen link, link-named refine quantities, a freed wrist, plots of every
# link, and the paper procedure with two flexible links.
set -uo pipefail
source "$(dirname "$0")/cli_test_env.sh"
fail=0
ok() { echo "ok   $*"; }
bad() { echo "FAIL $*"; fail=1; }

# 1. A run of the two-link arm: both links summarised; per-link datasets; the elbow (mounted on the
#    upper link's tip with no transform of its own) is where that tip is, at every output.
"$rfem" run "$src/cases/two_link_arm.toml" --set simulation.t_end=2 --json -o arm.h5 > arm.json \
  && ok "two-link arm runs" || bad "two-link arm run"
/usr/bin/python3 - <<'PY' && ok "per-link JSON and datasets; elbow on the upper tip" || bad "per-link outputs"
import json, sys, h5py, numpy as np
js = json.load(open("arm.json"))
run = js["runs"][0]
names = [l["name"] for l in run["links"]]
f = h5py.File("arm.h5", "r")
g = f["run"]
upper, fore = g["links/upper"], g["links/forearm"]
elbow = g["joint_position"][:, 3:6]
checks = [
    names == ["upper", "forearm"],
    run["peak_u1"] == run["links"][1]["peak_u1"] and run["links"][0]["peak_u1"] > 1e-3,
    list(g.attrs["link_names"]) == ["upper", "forearm"],
    np.array_equal(g["tip_deflection"][:], fore["tip_deflection"][:]),      # the soft link
    isinstance(g.get("tip_deflection", getlink=True), h5py.SoftLink),
    upper["rfe_centre"].shape == (8, 3) and fore["payload_position"].shape[1] == 3,
    np.max(np.abs(elbow - upper["tip_position"][:])) < 1e-12,
    np.max(np.abs(fore["payload_position"][:] - fore["tip_position"][:])) < 1e-12,   # the payload is at the tip
    abs(float(np.max(np.abs(upper["tip_deflection"][:, 0]))) - run["links"][0]["peak_u1"]) < 1e-15,
]
print(checks)
sys.exit(0 if all(checks) else 1)
PY

# 2. Statics: a dead load on the upper link's tip bends the upper link only (nothing loads the
#    forearm, which rides along undeformed); on the forearm's tip it bends both.
"$rfem" static "$src/cases/two_link_arm.toml" --json --set "loads.tip_force=[0, 0.5, 0]" --set loads.link=upper > up.json \
  && "$rfem" static "$src/cases/two_link_arm.toml" --json --set "loads.tip_force=[0, 0.5, 0]" > fore.json \
  && ok "statics with loads on either link" || bad "statics"
/usr/bin/python3 - <<'PY' && ok "a load bends what carries it" || bad "static tip loads"
import json, sys
up, fore = json.load(open("up.json")), json.load(open("fore.json"))
u = lambda js, i: js["links"][i]["tip_displacement"][1]
checks = [u(up, 0) > 1e-4, abs(u(up, 1)) < 1e-12 * u(up, 0), u(fore, 0) > 1e-4, u(fore, 1) > 1e-4,
          fore["tip_displacement"] == fore["links"][1]["tip_displacement"]]
print(checks, u(up, 0), u(up, 1), u(fore, 0), u(fore, 1))
sys.exit(0 if all(checks) else 1)
PY

# 3. Refinement with link-named quantities; an unknown prefix is one line, exit 2.
"$rfem" refine "$src/cases/two_link_arm.toml" --n 8,16,32 --quantity upper/peak:u1,forearm/u1@1 \
  --set simulation.t_end=1 --no-integration-check --json -o ref.h5 > ref.json 2> ref.err \
  && ok "refine of two links' quantities" || bad "refine: $(cat ref.err)"
/usr/bin/python3 - <<'PY' && ok "both link quantities converge at order ~2" || bad "refine orders"
import json, sys
js = json.load(open("ref.json"))
orders = [q["rows"][-1]["order"] for q in js["quantities"]]
print([q["quantity"] for q in js["quantities"]], orders)
sys.exit(0 if all(o is not None and 1.7 < o < 2.3 for o in orders) else 1)
PY
"$rfem" refine "$src/cases/two_link_arm.toml" --n 8,16 --quantity elbw/peak:u1 2> err.txt > /dev/null
[ $? = 2 ] && [ "$(wc -l < err.txt)" = 1 ] && grep -q "no run or link named 'elbw'" err.txt \
  && ok "unknown prefix: $(cat err.txt)" || bad "unknown prefix: $(cat err.txt)"

# 4. A wrist at a link's tip can be freed in a modal analysis: one rigid mode.
"$rfem" modes "$src/cases/wrist_payload.toml" --n 10 --free wrist --count 3 --json > wm.json && \
  /usr/bin/python3 -c "
import json, sys; m = json.load(open('wm.json'))['modes']
sys.exit(0 if m[0]['kind'] == 'rigid' and m[1]['frequency_hz'] > 0.1 else 1)" \
  && ok "wrist freed: rigid mode first" || bad "modes --free wrist"

# 5. Plots of the two-link run; the paper procedure with links 2 and 3 flexible.
rfem_plot arm.h5 -o figs > /dev/null && [ -s figs/run_tip.png ] && ok "plot of two links" || bad "plot"
"$rfem" run "$src/cases/paper_two_flexible.toml" --set simulation.t_end=2 -q -o p2.h5 \
  && /usr/bin/python3 -c "
import sys, h5py; f = h5py.File('p2.h5', 'r')
ok = all(f[g].attrs['status'] == 'completed' and 'links/link2/tip' in f[g] for g in ('rigid', 'kinematic', 'force'))
ok = ok and f['rigid/links/link2/tip'][:].max() == 0 and abs(f['kinematic/links/link2/tip'][:]).max() > 0
sys.exit(0 if ok else 1)" && ok "paper procedure with two flexible links" || bad "paper_two_flexible"
exit $fail
