#!/usr/bin/env bash
# Regenerates the result tables of docs/results/ (and the README's results
# table and tour pictures) from the studies, with fixed seeds.
#   scripts/reproduce_results.sh [NAME...]
# NAMEs (default: all, in this order; about an hour on 2 cores):
#   simulation  celc simulate --sweep all (500 trials, seed 1): simulation_*.md (1 min)
#   peers       celc simulate --study peers (500 trials, seed 1): peers.md, peers_*.png
#   scenes      scripts/scene_table.sh: scenes.md, shipped_scenes.md (8 min)
#   sample      celc run data/sample_seq: sample.md, docs/images/sample_*.png
#   sigma       scripts/sigma_calibration.sh: sigma_calibration.md, _sim.md, _bins.md, images/sigma_reliability.png (12 min)
#   parallax    scripts/parallax_study.sh: parallax.md (15 min after the scenes' renders)
#   rotation    scripts/rotation_trust.sh: rotation_trust.md (pure rotation, calibration errors; 2 min)
#   clusters    scripts/cluster_table.sh (12 held-out scenes, seed 30000): clusters.md (12 min)
#   speeds      the same at 1, 3 and 4 m/s (8 scenes, seed 50000, 0.3-3 rad/s): clusters_speeds.md (25 min)
#   lines       the same on scenes of straight bars only (8 scenes, seed 60000, 1-4 m/s, 0.3-3 rad/s): clusters_lines.md (8 min)
#   gap         every window of clusters, speeds and lines, pipeline against oracle: images/oracle_gap.png (after them)
#   seeds       clusters, speeds and lines again at cluster.seed 2 and 3: clusters_seeds.md (50 min after their renders)
#   derotate    clusters and speeds again with cluster.derotate true: clusters_derotate.md (5 min after their renders)
#   fast        clusters and speeds again with -c config/fast.yaml: fast.md (4 min after their renders)
#   cluster_test clusters, speeds and lines again with solver.ml.cluster_test 20: clusters_cluster_test.md (25 min after their renders)
#   acceleration scripts/acceleration_sweep.sh: acceleration_sweep.md (celc_acc against celc_ml, rho 0-30; 30 s)
#   accelerometer scripts/accelerometer_table.sh: accelerometer.md (the scenes with a still IMU start; 15 min)
#   studies     build/celc_acceleration_study, celc_rate_offset_study, celc_solve_path_study
#   summary     the README's results table from simulation, peers and scenes: summary.md;
#               then the tables the pages of docs/ include (<!-- include results/NAME.md -->)
# Each file's first line names the command that wrote it; the text after a
# file's tables (its legend) is kept. Work files go to ${CELC_RESULTS_WORK:-out/results}.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
build="${CELC_BUILD_DIR:-$root/build}"
[ -x "$build/celc" ] || scripts/setup.sh
celc="$build/celc"
work="${CELC_RESULTS_WORK:-$root/out/results}"
res="$root/docs/results"
py=/usr/bin/python3
tables="$py $root/scripts/results_tables.py"
mkdir -p "$work" "$res" "$root/docs/images"
names=("$@")
[ ${#names[@]} -gt 0 ] || names=(simulation peers scenes sample sigma parallax rotation clusters speeds lines gap seeds derotate fast cluster_test acceleration accelerometer studies summary)

put() {  # put FILE NAME COMMAND: stdin's tables into docs/results/FILE
  $tables put "$res/$1" "\`scripts/reproduce_results.sh $2\` (runs \`$3\`)"
  echo "wrote docs/results/$1" >&2
}

heldout_again() {  # heldout_again NAME PAGE ARGS...: the clusters and speeds sets again, celc run with ARGS
  local name="$1" page="$2"
  shift 2
  scripts/cluster_table.sh "$work/clusters" -- "$@" > "$work/${name}30.txt"
  for v in 1 3; do
    scripts/cluster_table.sh "$work/speed$v" --seed 50000 --count 8 --speed "$v,$v" --rate 0.3,3 -- "$@" \
      > "$work/$name$v.txt"
  done
  { echo "The 12 scenes of clusters.md (seed 30000):"; $tables table 1 < "$work/${name}30.txt"; echo;
    echo "At 1 m/s (clusters_speeds.md):"; $tables table 1 < "$work/${name}1.txt"; echo;
    echo "At 3 m/s:"; $tables table 1 < "$work/${name}3.txt"; } |
    put "$page" "$name" "scripts/cluster_table.sh [as for clusters, speeds] -- $*"
}

for name in "${names[@]}"; do
  case "$name" in
    simulation)
      cmd="celc simulate --sweep all --trials 500 --seed 1 --threads 2 -c config/simulate.yaml"
      "$celc" simulate --sweep all --trials 500 --seed 1 --threads 2 -c config/simulate.yaml \
        -o "$work/simulation" --force -q --no-plots > "$work/simulation.txt"
      $tables block "Default setting" < "$work/simulation.txt" | put simulation_default.md simulation "$cmd"
      for s in event_noise line_noise omega_noise speed interval lines; do
        $tables block "Sweep $s:" < "$work/simulation.txt" | put "simulation_$s.md" simulation "$cmd"
      done
      ;;
    peers)
      cmd="celc simulate --study peers -c config/peers.yaml --trials 500 --seed 1 --threads 2"
      "$celc" simulate --study peers -c config/peers.yaml --trials 500 --seed 1 --threads 2 \
        -o "$work/peers" --force -q --no-plots > /dev/null
      $py scripts/plot_peers.py "$work/peers"
      for p in grid ratio factors; do cp "$work/peers/peers_$p.png" "$res/peers_$p.png"; done
      cp "$work/peers/peers.csv" "$res/peers.csv"
      $tables table 0 < "$work/peers/peers_table.md" | put peers.md peers "$cmd; scripts/plot_peers.py"
      ;;
    scenes)
      scripts/scene_table.sh "$work/scenes" > "$work/scenes.txt"
      $tables table 1 < "$work/scenes.txt" | put scenes.md scenes "scripts/scene_table.sh"
      $tables table 0 < "$work/scenes.txt" | put shipped_scenes.md scenes "scripts/scene_table.sh"
      ;;
    sample)
      "$celc" run data/sample_seq -o "$work/sample" --force -q > /dev/null
      $tables windows "$work/sample/windows.csv" | put sample.md sample "celc run data/sample_seq"
      cp "$work/sample/velocity.png" docs/images/sample_velocity.png
      cp "$work/sample/error.png" docs/images/sample_error.png
      ;;
    sigma)
      scripts/sigma_calibration.sh "$work/sigma" > /dev/null
      put sigma_calibration_sim.md sigma "scripts/sigma_calibration.sh" < "$work/sigma/sim.md"
      { echo "Coverage of sigma_deg by D:"; echo; cat "$work/sigma/compact.md"; } |
        put sigma_calibration.md sigma "scripts/sigma_calibration.sh"
      put sigma_calibration_bins.md sigma "scripts/sigma_calibration.sh" < "$work/sigma/bins.md"
      cp "$work/sigma/reliability_rendered__input_errors.png" docs/images/sigma_reliability.png
      ;;
    parallax)
      scripts/parallax_study.sh "$work/scenes" > "$work/parallax.txt"
      $tables table 1 < "$work/parallax.txt" | put parallax.md parallax "scripts/parallax_study.sh"
      ;;
    rotation)
      scripts/rotation_trust.sh "$work/rotation" > "$work/rotation.txt"
      $tables table 0 < "$work/rotation.txt" | put rotation_trust.md rotation "scripts/rotation_trust.sh"
      ;;
    clusters)
      scripts/cluster_table.sh "$work/clusters" > "$work/clusters.txt"
      { $tables table 1 < "$work/clusters.txt"; echo; $tables table 0 < "$work/clusters.txt"; } |
        put clusters.md clusters "scripts/cluster_table.sh"
      ;;
    speeds)
      for v in 1 3 4; do
        scripts/cluster_table.sh "$work/speed$v" --seed 50000 --count 8 --speed "$v,$v" --rate 0.3,3 \
          > "$work/speed$v.txt"
      done
      { echo "At 1 m/s:"; $tables table 1 < "$work/speed1.txt"; echo; echo "At 3 m/s, the same scenes:";
        $tables table 1 < "$work/speed3.txt"; echo; echo "At 4 m/s, the same scenes:";
        $tables table 1 < "$work/speed4.txt"; echo; $tables table 0 < "$work/speed1.txt"; echo;
        $tables table 0 < "$work/speed3.txt"; echo; $tables table 0 < "$work/speed4.txt"; } |
        put clusters_speeds.md speeds "scripts/cluster_table.sh --seed 50000 --count 8 --speed V,V --rate 0.3,3, V = 1, 3 and 4"
      ;;
    lines)
      scripts/cluster_table.sh "$work/lines" --seed 60000 --count 8 --kinds lines --speed 1,4 --rate 0.3,3 \
        > "$work/lines.txt"
      { $tables table 1 < "$work/lines.txt"; echo; $tables table 0 < "$work/lines.txt"; } |
        put clusters_lines.md lines "scripts/cluster_table.sh --seed 60000 --count 8 --kinds lines --speed 1,4 --rate 0.3,3"
      ;;
    gap)
      /usr/bin/python3 scripts/plot_oracle_gap.py "$root/docs/images/oracle_gap.png" \
        "seed 30000=$work/clusters/run" "1 m/s=$work/speed1/run" "3 m/s=$work/speed3/run" \
        "4 m/s=$work/speed4/run" "bars, 1-4 m/s=$work/lines/run"
      ;;
    seeds)
      # The same scenes (rendered by clusters, speeds and lines) run again
      # with other RANSAC seeds of the clustering.
      sets=("seed 30000=clusters:" "1 m/s=speed1:--seed 50000 --count 8 --speed 1,1 --rate 0.3,3"
            "3 m/s=speed3:--seed 50000 --count 8 --speed 3,3 --rate 0.3,3"
            "4 m/s=speed4:--seed 50000 --count 8 --speed 4,4 --rate 0.3,3"
            "bars, 1-4 m/s=lines:--seed 60000 --count 8 --kinds lines --speed 1,4 --rate 0.3,3")
      specs=()
      for entry in "${sets[@]}"; do
        label="${entry%%=*}" rest="${entry#*=}"
        dir="${rest%%:*}" draw="${rest#*:}"
        for s in 2 3; do
          # shellcheck disable=SC2086  # draw holds several arguments
          scripts/cluster_table.sh "$work/$dir" $draw --runs "seed$s" -- --set "cluster.seed=$s" > /dev/null
        done
        specs+=("$label=$work/$dir/run,$work/$dir/seed2,$work/$dir/seed3")
      done
      $py scripts/seed_spread.py "${specs[@]}" |
        put clusters_seeds.md seeds "scripts/cluster_table.sh [as for clusters, speeds, lines] --runs seedS -- --set cluster.seed=S, S = 2 and 3; scripts/seed_spread.py"
      ;;
    derotate)
      heldout_again derotate clusters_derotate.md --set cluster.derotate=true
      ;;
    cluster_test)
      # The five held-out sets again, celc_ml leaving out the clusters that
      # disagree with the others (its oracle too: the same options).
      test=(--set solver.ml.cluster_test=20)
      scripts/cluster_table.sh "$work/clusters" --runs cluster_test -- "${test[@]}" > "$work/cluster_test30.txt"
      for v in 1 3 4; do
        scripts/cluster_table.sh "$work/speed$v" --seed 50000 --count 8 --speed "$v,$v" --rate 0.3,3 \
          --runs cluster_test -- "${test[@]}" > "$work/cluster_test$v.txt"
      done
      scripts/cluster_table.sh "$work/lines" --seed 60000 --count 8 --kinds lines --speed 1,4 --rate 0.3,3 \
        --runs cluster_test -- "${test[@]}" > "$work/cluster_test_lines.txt"
      { echo "The 12 scenes of clusters.md (seed 30000):"; $tables table 1 < "$work/cluster_test30.txt"; echo;
        for v in 1 3 4; do
          echo "At $v m/s (clusters_speeds.md):"; $tables table 1 < "$work/cluster_test$v.txt"; echo
        done
        echo "The bars (clusters_lines.md):"; $tables table 1 < "$work/cluster_test_lines.txt"; } |
        put clusters_cluster_test.md cluster_test \
          "scripts/cluster_table.sh [as for clusters, speeds, lines] --runs cluster_test -- --set solver.ml.cluster_test=20"
      ;;
    fast)
      heldout_again fast fast.md -c config/fast.yaml
      ;;
    acceleration)
      scripts/acceleration_sweep.sh 200 "$work/acceleration" > "$work/acceleration.txt"
      $tables table 0 < "$work/acceleration.txt" | put acceleration_sweep.md acceleration "scripts/acceleration_sweep.sh 200"
      ;;
    accelerometer)
      scripts/accelerometer_table.sh "$work/accelerometer" > "$work/accelerometer.txt"
      put accelerometer.md accelerometer "scripts/accelerometer_table.sh" < "$work/accelerometer.txt"
      ;;
    studies)
      for s in acceleration rate_offset solve_path; do
        [ -x "$build/celc_${s}_study" ] || { echo "no $build/celc_${s}_study (CELC_BUILD_BENCHMARKS=ON)" >&2; exit 1; }
        "$build/celc_${s}_study" > "$work/$s.txt"
        $tables table 0 < "$work/$s.txt" | put "$s.md" studies "build/celc_${s}_study"
      done
      ;;
    summary)
      $tables summary "$res" | put summary.md summary "scripts/results_tables.py summary docs/results"
      $tables readme README.md "$res/summary.md"
      echo "rewrote the README's results table" >&2
      $tables include docs/*.md
      ;;
    *)
      echo "reproduce_results.sh: unknown name '$name' (see the header of this script)" >&2
      exit 2
      ;;
  esac
done
