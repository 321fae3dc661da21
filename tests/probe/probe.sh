#!/usr/bin/env bash
# A hostile user's probe of the command line (issue 37's classes): outputs aimed at inputs
# and at each other, existing files, special files for every file key, standard output
# closed or full, files whose contents must not leak, results that cannot be true and
# errors that must name what the user wrote. Not run in CI (about two minutes on two
# cores with a release binary); run it by hand:
#
#     tests/probe/probe.sh target/release/rosette
#
# Each case states the exit codes it accepts and the words its message must (or must not)
# hold; a case is clean when its exit code is one of those, nothing panicked or hung (60 s),
# no message holds a number of 20 digits or more, every protected file (the inputs) is
# byte-for-byte as it was, and no secret planted in a file or the environment shows.
# Prints one line per case that is not clean, then the counts.

set -u
# Seconds before a case counts as hung (PROBE_TIMEOUT=10 for a quick look at an old binary).
LIMIT=${PROBE_TIMEOUT:-60}
BIN=$(realpath "${1:-target/release/rosette}")
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
WORK=$(mktemp -d "${TMPDIR:-/tmp}/rosette-probe.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
cd "$WORK" || exit 1
export RAYON_NUM_THREADS=1 ROSETTE_PROBE_SECRET=hunter3env

cases=0
clean=0
unclean=0
PROTECTED=()

# checksum of every protected file, one line each
sums() { for f in "${PROTECTED[@]}"; do printf '%s %s\n' "$f" "$(sha256sum <"$f" 2>/dev/null | cut -c1-16)"; done; }

# probe NAME CODES MUST MUSTNOT -- COMMAND...
#   CODES: space-separated accepted exit codes; MUST / MUSTNOT: '|'-separated words ('' none)
probe() {
    local name=$1 codes=$2 must=$3 mustnot=$4
    shift 5
    cases=$((cases + 1))
    local before after code out why=""
    before=$(sums)
    out=$(timeout "$LIMIT" "$@" 2>&1 >"$WORK/stdout.txt")
    code=$?
    after=$(sums)
    [[ " $codes " == *" $code "* ]] || why+="exit $code (wanted $codes); "
    [[ $code == 124 ]] && why+="hung; "
    [[ $out == *panicked* ]] && why+="panic; "
    grep -Eq '[0-9]{20,}' <<<"$out" && why+="a 20-digit number; "
    [[ $before == "$after" ]] || why+="an input was changed; "
    for secret in hunter2hash hunter3env 'root:x'; do
        [[ $out == *"$secret"* ]] && why+="leaks $secret; "
    done
    if [[ -n $must ]]; then
        IFS='|' read -ra words <<<"$must"
        for w in "${words[@]}"; do [[ $out == *"$w"* ]] || why+="does not name '$w'; "; done
    fi
    if [[ -n $mustnot ]]; then
        IFS='|' read -ra words <<<"$mustnot"
        for w in "${words[@]}"; do [[ $out == *"$w"* ]] && why+="says '$w'; "; done
    fi
    if [[ -z $why ]]; then
        clean=$((clean + 1))
    else
        unclean=$((unclean + 1))
        printf 'NOT CLEAN  %s: %s\n           %s\n' "$name" "$why" "$(head -c 400 <<<"$out" | tr '\n' ' ')"
    fi
}

# --- inputs -----------------------------------------------------------------------------
cp "$ROOT/presets/fabrics/wool.toml" fabric.toml
cp "$ROOT/presets/fabrics/cotton-poplin.toml" sheet.toml
printf 'v 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nv 0 0 0.01\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n' >prop.obj
sed "s|^preset = .*|preset = \"$WORK/fabric.toml\"|" "$ROOT/presets/cusick-drape-30.toml" >scene.toml
printf '\n[[props]]\nname = "pebble"\nshape = "mesh"\nfile = "%s"\nposition = [0.5, 0.5, -0.4]\n' "$WORK/prop.obj" >>scene.toml
cp scene.toml scene.png; cp scene.toml scene.glb
cp fabric.toml fabric.png; cp fabric.toml fabric.glb
ln -s scene.toml link-scene.toml; ln fabric.toml hard-fabric.toml
printf 'root:x:0:0:hunter2hash:/root:/bin/bash\n' >shadow
printf 'v hunter2hash 0 0\nf 1 2 3\n' >secret-mesh
printf 'my only notes\n' >notes.txt; cp notes.txt notes.csv; cp notes.txt notes.json
printf 'not a picture\n' >photo.png; printf 'not a model\n' >model.glb
printf '# my sheet\n[kes]\nW = 13.7\n' >hand.toml
cp sheet.toml d14.json
mkfifo fifo.toml
python3 -c "import socket; s=socket.socket(socket.AF_UNIX); s.bind('$WORK/socket.toml')" 2>/dev/null
mkdir folder
PROTECTED=(scene.toml scene.png scene.glb fabric.toml fabric.png fabric.glb prop.obj sheet.toml notes.txt notes.csv notes.json photo.png model.glb hand.toml d14.json shadow)

S="$WORK/scene.toml"
QUICK=(--duration 0.004 --max-wall 20)

# --- 1. outputs against inputs ------------------------------------------------------------
for flag in --metrics --outline --step-log; do
    for input in scene.toml fabric.toml prop.obj ./scene.toml link-scene.toml hard-fabric.toml "$WORK/../$(basename "$WORK")/fabric.toml"; do
        probe "run $flag $input (an input)" 2 "$flag" "" -- "$BIN" run "$S" "${QUICK[@]}" "$flag" "$input"
    done
done
for input in scene.png fabric.png; do
    spec=$S; [[ $input == scene.png ]] && spec="$WORK/scene.png"
    fab=$([[ $input == fabric.png ]] && echo "--set fabric.preset=$WORK/fabric.png")
    probe "run --screenshot $input (an input)" 2 "--screenshot" "" -- "$BIN" run "$spec" $fab "${QUICK[@]}" --screenshot "$input"
done
for input in scene.glb fabric.glb; do
    spec=$S; [[ $input == scene.glb ]] && spec="$WORK/scene.glb"
    fab=$([[ $input == fabric.glb ]] && echo "--set fabric.preset=$WORK/fabric.glb")
    probe "run --export $input (an input)" 2 "--export" "" -- "$BIN" run "$spec" $fab "${QUICK[@]}" --export "$input"
done
probe "fabric import s.toml --out s.toml" 2 "--out" "" -- "$BIN" fabric import sheet.toml --out sheet.toml --force
probe "fabric import s.toml --out ./s.toml" 2 "--out" "" -- "$BIN" fabric import sheet.toml --out ./sheet.toml
probe "card d14.json --out ." 2 "--out" "" -- "$BIN" card d14.json --out . --force
probe "compare d14.json silk --out d14.png" 2 "--out" "" -- "$BIN" compare d14.json silk --out d14.png --force
# two outputs in one file
for pair in "--metrics --step-log" "--metrics --outline" "--outline --step-log"; do
    set -- $pair
    probe "run $1 x $2 x" 2 "$1|$2|same file" "" -- "$BIN" run "$S" "${QUICK[@]}" "$1" out.csv "$2" ./out.csv
done
probe "run --metrics x --screenshot x (same name)" 2 "same file" "" -- "$BIN" run "$S" "${QUICK[@]}" --metrics shot.png --screenshot shot.png
# existing files that are not Rosette's
probe "--metrics over a note" 2 "--force" "" -- "$BIN" run cantilever --duration 0.01 --metrics notes.txt
probe "--outline over a note" 2 "--force" "" -- "$BIN" run cusick-drape-30 --duration 0.004 --outline notes.csv
probe "--step-log over a note" 2 "--force" "" -- "$BIN" run cantilever --duration 0.01 --step-log notes.csv
probe "--screenshot over a photo" 2 "--force" "" -- "$BIN" run cantilever --duration 0.01 --screenshot photo.png
probe "--export over a model" 2 "--force" "" -- "$BIN" run cantilever --duration 0.01 --export model.glb
probe "import over a hand sheet" 2 "--force" "" -- "$BIN" fabric import cotton-poplin --out hand.toml
probe "--metrics over a folder" 2 "folder" "" -- "$BIN" run cantilever --duration 0.01 --metrics folder
probe "--metrics into a missing folder" 2 "no-such" "" -- "$BIN" run cantilever --duration 0.01 --metrics no-such/m.json
probe "--metrics to /dev/null (a stream)" 0 "" "" -- "$BIN" run cantilever --duration 0.01 --metrics /dev/null
probe "--metrics to /dev/full" 4 "--metrics" "" -- "$BIN" run cantilever --duration 0.01 --metrics /dev/full
probe "chart --out over someone's table" 2 "accuracy.csv" "" -- bash -c "mkdir -p c && echo x >c/accuracy.csv && exec '$BIN' chart --quick --out c"
probe "bench --out over someone's table" 2 "bench.csv" "" -- bash -c "mkdir -p b && echo x >b/bench.csv && exec '$BIN' bench --quick --threads 1 --out b"
probe "bench --out a file" 2 "--out" "" -- "$BIN" bench --quick --out notes.txt

# --- 2. special files for every file key -----------------------------------------------------
for special in /dev/zero /dev/urandom "$WORK/fifo.toml" "$WORK/socket.toml" "$WORK/folder"; do
    [[ -e $special ]] || continue
    probe "run SCENE=$special" 2 "$special" "" -- "$BIN" run "$special"
    probe "fabric.preset=$special" 2 "$special" "" -- "$BIN" run cantilever --set "fabric.preset=$special"
    probe "props[0].file=$special" 2 "$special" "" -- "$BIN" run cusick-drape-30 --set "props=[{shape='mesh', file='$special'}]"
    probe "card $special" 2 "$special" "" -- "$BIN" card "$special" --out folder
    probe "compare $special" 2 "$special" "" -- "$BIN" compare "$special" silk --out cmp.png
    probe "fabric import $special" 2 "$special" "" -- "$BIN" fabric import "$special"
    probe "fabric check $special" 2 "$special" "" -- "$BIN" fabric check "$special"
done

# --- 3. standard output and error closed or full ------------------------------------------
for cmd in "presets" "fabric list" "fabric template" "fabric import cotton-poplin" "run cantilever --duration 0.01" "run cantilever --duration 0.01 --metrics -"; do
    probe "$cmd | (closed)" 0 "" "error" -- bash -c "exec '$BIN' $cmd | true"
    probe "$cmd > /dev/full" 4 "standard output" "" -- bash -c "exec '$BIN' $cmd >/dev/full"
done
probe "presets | head -1" 0 "" "" -- bash -c "'$BIN' presets | head -1 && '$BIN' presets >/dev/null"
probe "run 2>/dev/full" 0 "" "" -- bash -c "exec '$BIN' run cantilever --duration 0.01 2>/dev/full"
probe "refusal 2>/dev/full" 2 "" "" -- bash -c "exec '$BIN' run cantilever --set fabric.areal_density=-1 2>/dev/full"

# --- 4. leaks ------------------------------------------------------------------------------
probe "fabric.preset=shadow" 2 "not a fabric file" "" -- "$BIN" run cantilever --set "fabric.preset=$WORK/shadow"
probe "fabric.preset=/etc/passwd" 2 "not a fabric file" "" -- "$BIN" run cantilever --set fabric.preset=/etc/passwd
probe "fabric.preset=/proc/self/environ" 2 "not a fabric file" "" -- "$BIN" run cantilever --set fabric.preset=/proc/self/environ
probe "run shadow" 2 "not a scene file" "" -- "$BIN" run "$WORK/shadow"
probe "card shadow" 2 "not a fabric file" "" -- "$BIN" card "$WORK/shadow" --out folder
probe "fabric import shadow" 2 "not a fabric file" "" -- "$BIN" fabric import "$WORK/shadow"
probe "compare shadow" 2 "not a fabric file" "" -- "$BIN" compare "$WORK/shadow" silk --out cmp.png
probe "mesh prop secret-mesh" 2 "not an OBJ mesh" "" -- "$BIN" run cusick-drape-30 --set "props=[{shape='mesh', file='$WORK/secret-mesh'}]"

# --- 5. results that cannot be true --------------------------------------------------------
probe "DC of a cloth that has not fallen" 0 "drape_coefficient not measured" "" -- bash -c "'$BIN' run cusick-drape-30 --duration 0.004 --metrics - | grep -q notes"
probe "wrinkles at the seed's height" 0 "no wrinkles counted" "" -- "$BIN" run shear-buckling --duration 0.004
probe "max_strain beyond the duration" 2 "test.max_strain|scene.duration" "" -- "$BIN" run tensile-warp --set test.max_strain=0.5
probe "end_shortening beyond the duration" 2 "test.end_shortening" "" -- "$BIN" run euler-buckling --set test.speed=1e-6
probe "shear angle beyond the duration" 2 "--set test.speed" "" -- "$BIN" run shear-buckling --set test.speed=1e-4
probe "a short --duration notes the pull" 0 "not reached" "" -- "$BIN" run tensile-warp --duration 0.5
probe "dt longer than --duration" 2 "--duration 0.2" "scene.duration" -- "$BIN" run cantilever --duration 0.2 --set solver.dt=1
probe "fast dt longer than --duration" 2 "--duration" "" -- "$BIN" run cusick-drape-30 --fast --duration 0.01
probe "sphere height" 2 "props[0].height" "" -- "$BIN" run cusick-drape-30 --set "props=[{shape='sphere', radius=0.09, height=0.3, position=[0,0,-0.09]}]"
probe "ground radius" 2 "props[1].radius" "" -- "$BIN" run sphere-drop --set "props=[{shape='sphere', radius=0.25}, {shape='ground', radius=2, position=[0,0,-0.25]}]"
probe "box with a file" 2 "props[0].file" "" -- "$BIN" run cusick-drape-30 --set "props=[{shape='box', size=[0.1,0.1,0.1], file='x.obj', position=[0,0,-0.05]}]"
probe "ball through the cloth" 2 "through the cloth" "" -- "$BIN" run sphere-drop --set mesh.edge_length=0.04 --set "props=[{shape='sphere', radius=0.25, position=[0,0,0.2]}]"
probe "pedestal through the cloth" 2 "through the cloth" "" -- "$BIN" run cusick-drape-30 --set "props=[{shape='cylinder', radius=0.09, height=0.3, position=[0,0,0.1]}]"
probe "camera at 1e300 m" 2 "--camera" "" -- "$BIN" run cantilever --duration 0.01 --screenshot far.png --camera -60,30,1e300
probe "camera at 500 m" 2 "pixels" "" -- "$BIN" run cantilever --duration 0.01 --screenshot far.png --camera -60,30,500
probe "camera at 1e-9 m" 2 "--camera" "" -- "$BIN" run cantilever --duration 0.01 --screenshot far.png --camera -60,30,1e-9
probe "bench --threads 0" 2 "--threads" "" -- "$BIN" bench --threads 0
probe "bench --threads 100000" 2 "--threads" "" -- "$BIN" bench --threads 100000
probe "fabric file with preset" 2 "preset" "" -- bash -c "(echo 'preset = \"denim\"'; cat fabric.toml) >inherit.toml && exec '$BIN' run cantilever --set fabric.preset=$WORK/inherit.toml"
probe "compare --set fabric.preset" 2 "--set fabric.preset=denim" "" -- "$BIN" compare silk wool --set fabric.preset=denim
probe "compare --set fabric table" 2 "compare drapes" "" -- "$BIN" compare silk wool --set "fabric={preset='denim'}"

# --- 6. errors that name what the user wrote ----------------------------------------------
probe "kes.LT_warp" 2 "--set fabric.kes.LT_warp=0.001|kes.LT_warp" "(bundled):" -- "$BIN" run cantilever --set fabric.preset=wool-worsted --set fabric.kes.LT_warp=0.001
probe "c_bias = 1000" 2 "cantilever.c_bias" "shorter" -- "$BIN" run cantilever --set fabric.preset=cotton-poplin --set fabric.cantilever.c_bias=1000
probe "Mg/cm²" 2 "case-sensitive" "" -- "$BIN" run cantilever --set fabric.preset=wool-worsted --set 'fabric.kes.W="16.8 Mg/cm²"'
probe "N/M" 2 "case-sensitive" "" -- "$BIN" run cantilever --set fabric.preset=wool-plain-fast --set 'fabric.fast.G="26 n/m"'
probe "kes.W = 1e300" 2 "kes.W|mg/cm²" "fabric.areal_density" -- "$BIN" run cantilever --set fabric.preset=wool-worsted --set fabric.kes.W=1e300
probe "kes.EMT = 500 %" 2 "kes.EMT_warp|%" "" -- "$BIN" run cantilever --set fabric.preset=wool-worsted --set fabric.kes.EMT_warp=500
probe "areal_density=-1e300" 2 "fabric.areal_density" "" -- "$BIN" run cantilever --set fabric.areal_density=-1e300
probe "perturbation=1e300" 2 "test.perturbation" "" -- "$BIN" run cusick-drape-30 --set test.perturbation=1e300
probe "damping=1e300" 2 "solver.damping" "" -- "$BIN" run cantilever --set solver.damping=1e300
probe "friction=1e300" 2 "contact.friction_static" "" -- "$BIN" run cusick-drape-30 --set contact.friction_static=1e300
probe "curve strain -1e300" 2 "fabric.tensile_warp" "" -- "$BIN" run cantilever --set "fabric.tensile_warp=[[0,0],[-1e300,5]]"
probe "prop radius -1e300" 2 "radius" "" -- "$BIN" run cusick-drape-30 --set "props=[{shape='sphere', radius=-1e300}]"
probe "dt 1e-300" 2 "solver.dt" "" -- "$BIN" run cantilever --set solver.dt=1e-300
probe "--max-steps vs --duration" 0 "" "" -- "$BIN" run cantilever --duration 0.01 --max-steps 3
probe "--max-steps named" 2 "--max-steps 3" "scene.max_steps" -- "$BIN" run cantilever --max-steps 3
probe "--set not blamed on the bundled file" 2 "--set test.speed" "(bundled)" -- "$BIN" run tensile-warp --set test.speed=1e-300
probe "cg advice" 5 "cg_max_iterations (now 1" "" -- "$BIN" run cantilever --set solver.newton.cg_max_iterations=1 --duration 0.05
probe "divergence advice (explicit)" 3 "implicit-euler" "" -- "$BIN" run tensile-warp --set solver.integrator=symplectic-euler --set solver.dt=0.001
probe "--duration nan" 2 "--duration" "" -- "$BIN" run cantilever --duration nan
probe "--max-wall -1" 2 "--max-wall" "" -- "$BIN" run cantilever --max-wall -1
probe "--export-frames 1" 2 "--export-frames" "" -- "$BIN" run cantilever --duration 0.01 --export a.glb --export-frames 1

echo "cases: $cases, clean: $clean, not clean: $unclean"
[[ $unclean == 0 ]]
