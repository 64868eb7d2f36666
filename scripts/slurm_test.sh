#!/usr/bin/env bash
# One-node Slurm test of scripts/slurm_batch.sh.
#   scripts/slurm_test.sh            (needs build/celc: scripts/setup.sh first)
# Installs slurm-wlm and munge when missing (apt-get, through sudo when not
# root), then, all inside a temporary folder and on free local ports:
#   - a munge key of its own and a munged on its own socket,
#   - slurm.conf for one node `localhost` (127.0.0.1) with this machine's CPUs
#     and memory (`slurmd -C`), proctrack/linuxproc, task/none, no cgroups,
#     no accounting, state / spool / logs in the temporary folder,
#   - slurmctld and slurmd in the background (-f and SLURM_CONF: /etc/slurm
#     and /etc/munge are never read or written),
# waits until the node is idle, then runs a two-sequence batch on the bundled
# sample (data/sample_seq) once unsharded (`celc batch`) and once as a Slurm
# array (`sbatch --array=1-N --wait scripts/slurm_batch.sh`), and compares:
#   1. per sequence, the shards' windows.csv rows, concatenated and sorted by
#      window index (stable), with the unsharded rows: every column but
#      runtime_ms (a wall-clock time), byte for byte; each shard K holding
#      only windows with index % N == K-1, all with the same header;
#   2. `celc table SHARDS/shard_*` (shards merged per sequence) with the
#      unsharded batch's table.csv, byte for byte.
# Exit status 0 only when both match. The daemons it started are stopped
# (and any job step they left) and the folder removed on every exit.
# Environment: CELC_BUILD_DIR (default build), CELC_SLURM_SHARDS (default 3),
#   CELC_SLURM_TIMEOUT (seconds for the array, default 300),
#   CELC_SLURM_PORT (first port tried, default 16817),
#   CELC_SLURM_KEEP=1 keeps the temporary folder (its path is printed).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${CELC_BUILD_DIR:-$root/build}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
shards="${CELC_SLURM_SHARDS:-3}"
job_timeout="${CELC_SLURM_TIMEOUT:-300}"
say() { echo "slurm_test: $*" >&2; }
die() { say "error: $*"; exit 1; }

# --- packages (the pattern of scripts/setup.sh) -----------------------------
packages=(slurm-wlm munge)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  say "installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi
# slurmd starts jobs as the submitting user and must run as root: the test
# runs as root (through sudo when it is not; untested here).
if [ "$(id -u)" -ne 0 ]; then
  say "re-running as root through sudo"
  pass=("CELC_BUILD_DIR=$build")
  for v in CELC_SLURM_SHARDS CELC_SLURM_TIMEOUT CELC_SLURM_PORT CELC_SLURM_KEEP TMPDIR; do
    [ -z "${!v:-}" ] || pass+=("$v=${!v}")
  done
  exec sudo env "${pass[@]}" "$0" "$@"
fi
t_begin=$SECONDS  # after the install: the measured time is start-up, runs and comparison
for tool in munged mungekey munge unmunge slurmctld slurmd sinfo sbatch squeue scancel scontrol timeout; do
  command -v "$tool" >/dev/null || die "$tool not found (Debian packages slurm-wlm, munge, coreutils)"
done
celc="$build/celc"
[ -x "$celc" ] || die "$celc not found: build it first (scripts/setup.sh, or cmake --build build --target celc)"
case "$shards" in '' | *[!0-9]* | 0) die "CELC_SLURM_SHARDS '$shards' is not a positive whole number" ;; esac
[ -d "$root/data/sample_seq" ] || die "$root/data/sample_seq not found"

# --- temporary cluster ------------------------------------------------------
tmp="$(mktemp -d "${TMPDIR:-/tmp}/celc-slurm.XXXXXX")"
chmod 755 "$tmp"  # munged wants its socket folder and every parent executable by all
mkdir -m 755 "$tmp/munge"
mkdir -m 700 "$tmp/etc" "$tmp/state" "$tmp/spool" "$tmp/log" "$tmp/run" "$tmp/jobs"
munged_pid="" ctld_pid="" slurmd_pid="" failed_phase=""
export SLURM_CONF="$tmp/etc/slurm.conf"

tail_logs() {
  local f
  for f in "$tmp"/log/*.log "$tmp"/log/*.out "$tmp"/jobs/*.out; do
    [ -s "$f" ] || continue
    case "$f" in */slurmctld.out | */slurmd.out) [ -s "${f%.out}.log" ] && continue ;; esac
    echo "----- last lines of $f" >&2
    tail -n 25 "$f" >&2
  done
}
stop_pid() {  # PID NAME: TERM, up to 15 s, then KILL
  local pid="$1" i
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null || return 0
  kill -TERM "$pid" 2>/dev/null || true
  for ((i = 0; i < 150; i++)); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  if kill -0 "$pid" 2>/dev/null; then
    say "$2 (pid $pid) did not stop in 15 s: KILL"
    kill -KILL "$pid" 2>/dev/null || true
  fi
  wait "$pid" 2>/dev/null || true
}
stray_steps() {  # slurmstepd processes of this cluster (cwd or a file open in $tmp)
  local d l comm
  for d in /proc/[0-9]*; do
    comm=""
    read -r comm 2>/dev/null <"$d/comm" || true
    [ "$comm" = slurmstepd ] || continue
    for l in "$d/cwd" "$d"/fd/*; do
      l="$(readlink "$l" 2>/dev/null || true)"
      if [ "$l" = "$tmp" ] || [[ "$l" == "$tmp"/* ]]; then
        echo "${d#/proc/}"
        break
      fi
    done
  done
}
cleanup() {
  local rc=$? i pid
  set +e
  trap - EXIT INT TERM
  if [ -n "$ctld_pid" ] && kill -0 "$ctld_pid" 2>/dev/null; then
    scancel --quiet --full "--user=$(id -un)" 2>/dev/null
    for ((i = 0; i < 100; i++)); do
      [ -z "$(squeue -h -o %i 2>/dev/null)" ] && break
      sleep 0.2
    done
  fi
  if [ "$rc" -ne 0 ]; then
    say "FAILED${failed_phase:+ ($failed_phase)}; daemon and job logs:"
    tail_logs
  fi
  stop_pid "$slurmd_pid" slurmd
  stop_pid "$ctld_pid" slurmctld
  for pid in $(stray_steps); do
    say "stopping job step slurmstepd (pid $pid)"
    kill -KILL "$pid" 2>/dev/null
  done
  stop_pid "$munged_pid" munged
  if [ "${CELC_SLURM_KEEP:-0}" = 1 ]; then
    say "kept $tmp"
  else
    rm -rf "$tmp"
  fi
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

port_free() { ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
port="${CELC_SLURM_PORT:-16817}"
while ! port_free "$port" || ! port_free "$((port + 1))"; do
  port=$((port + 2))
  [ "$port" -lt 65000 ] || die "no two free local ports from ${CELC_SLURM_PORT:-16817}"
done

# munge: a throwaway key and a daemon on its own socket
failed_phase="munged start-up"
mungekey --create --keyfile="$tmp/munge/munge.key" 2>"$tmp/log/mungekey.log" ||
  die "mungekey failed: $(cat "$tmp/log/mungekey.log")"
chmod 600 "$tmp/munge/munge.key"
munge_socket="$tmp/munge/munge.socket"
munged --foreground --key-file="$tmp/munge/munge.key" --socket="$munge_socket" \
  --pid-file="$tmp/run/munged.pid" --log-file="$tmp/log/munged.log" \
  --seed-file="$tmp/munge/munged.seed" >"$tmp/log/munged.out" 2>&1 &
munged_pid=$!
for ((i = 0; i < 100; i++)); do
  munge -n -S "$munge_socket" 2>/dev/null | unmunge -S "$munge_socket" >/dev/null 2>&1 && break
  kill -0 "$munged_pid" 2>/dev/null || die "munged exited"
  sleep 0.1
done
[ "$i" -lt 100 ] || die "munged does not answer on $munge_socket after 10 s"

# the node as slurmd sees the machine (CPUs, sockets, cores, threads, memory)
node="$(slurmd -C 2>/dev/null | grep -m1 '^NodeName=' || true)"
if [ -z "$node" ]; then
  node="NodeName=x CPUs=$(nproc) RealMemory=$(($(awk '/^MemTotal:/ {print $2}' /proc/meminfo) / 1024))"
fi
node="NodeName=localhost NodeAddr=127.0.0.1 ${node#NodeName=* }"
me="$(id -un)"
cat >"$SLURM_CONF" <<EOF
# Throwaway one-node cluster of scripts/slurm_test.sh
ClusterName=celctest
SlurmctldHost=localhost(127.0.0.1)
SlurmUser=$me
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$munge_socket
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/run/slurmctld.pid
SlurmdPidFile=$tmp/run/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
PlugStackConfig=$tmp/etc/plugstack.conf
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
MailProg=/bin/true
ReturnToService=2
SlurmdParameters=config_overrides
SlurmctldTimeout=30
SlurmdTimeout=60
InactiveLimit=0
KillWait=5
# sbatch --wait polls after 2, 8, 32, 32... s, but never longer than half of
# MinJobAge (so that no finished job is purged unseen): every 8 s here.
MinJobAge=16
$node State=UNKNOWN
PartitionName=celctest Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
: >"$tmp/etc/plugstack.conf"
# Jobs use no cgroups (linuxproc, task/none, no accounting), but slurmd 22.05
# loads a cgroup plugin at start anyway (`CgroupPlugin=disabled` is not known
# to it): autodetect picks v1 or v2; IgnoreSystemd lets v2 start without
# systemd (this machine has v1, so that path is untested).
printf '%s\n' CgroupPlugin=autodetect IgnoreSystemd=yes IgnoreSystemdOnFailure=yes >"$tmp/etc/cgroup.conf"

failed_phase="Slurm start-up"
slurmctld -D -c -f "$SLURM_CONF" >"$tmp/log/slurmctld.out" 2>&1 &
ctld_pid=$!
slurmd -D -N localhost -f "$SLURM_CONF" >"$tmp/log/slurmd.out" 2>&1 &
slurmd_pid=$!
state=""
for ((i = 0; i < 600; i++)); do
  state="$(sinfo -h -N -n localhost -o %t 2>/dev/null || true)"
  [ "$state" = idle ] && break
  kill -0 "$ctld_pid" 2>/dev/null || die "slurmctld exited"
  kill -0 "$slurmd_pid" 2>/dev/null || die "slurmd exited"
  sleep 0.1
done
[ "$state" = idle ] || die "node localhost not idle after 60 s (state '${state:-none}'; $(sinfo -h -R 2>/dev/null))"
t_up=$SECONDS
say "one-node Slurm up in $((t_up - t_begin)) s (ports $port, $((port + 1)); $node)"

# --- the batch, unsharded ---------------------------------------------------
failed_phase="unsharded celc batch"
batch="$tmp/batch.yaml"
cat >"$batch" <<EOF
# two sequences of the bundled sample, 10 and 7 windows of 20,000 events
sequences:
  - label: room
    path: $root/data/sample_seq
    config:
      windows: {policy: events, events: 20000}
      motion: {model: constant_twist}
  - label: room_gyro
    path: $root/data/sample_seq
    t_end: 0.2
    config:
      windows: {policy: events, events: 20000}
      motion: {model: gyro_integrated}
EOF
export CELC_NO_PLOTS=1
"$celc" batch "$batch" -o "$tmp/full" --threads 2 -q >"$tmp/log/full.out" 2>&1 ||
  die "celc batch (unsharded) failed: $(tail -n 5 "$tmp/log/full.out")"
t_full=$SECONDS

# --- the batch as a Slurm array ---------------------------------------------
# Submitted from the temporary folder (not the repository), without
# CELC_ROOT, so slurm_batch.sh must find the repository by itself; one CPU
# per task (the unsharded run used two threads: the rows must not depend on it).
failed_phase="Slurm array job"
say "sbatch --array=1-$shards --wait scripts/slurm_batch.sh (timeout ${job_timeout} s)"
(cd "$tmp" && env -u CELC_ROOT timeout "$job_timeout" sbatch --wait --quiet --array="1-$shards" \
  --cpus-per-task=1 --output="$tmp/jobs/slurm-%A_%a.out" \
  "$root/scripts/slurm_batch.sh" "$batch" "$tmp/shards") ||
  die "the array job failed or timed out (sbatch exit $?)"
t_array=$SECONDS

# --- comparison -------------------------------------------------------------
failed_phase="comparison"
drop_runtime() {  # CSV on stdin without its runtime_ms column, header kept
  awk -F, -v OFS=, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "runtime_ms") c = i;
      if (!c) { print "no runtime_ms column" > "/dev/stderr"; exit 1 } }
    { out = ""; sep = ""; for (i = 1; i <= NF; i++) if (i != c) { out = out sep $i; sep = OFS }; print out }'
}
fail=0
labels=(room room_gyro)
for label in "${labels[@]}"; do
  ref="$tmp/full/$label/windows.csv"
  [ -f "$ref" ] || { say "missing $ref"; fail=1; continue; }
  header="$(head -n1 "$ref")"
  : >"$tmp/rows_$label.csv"
  for ((k = 1; k <= shards; k++)); do
    f="$tmp/shards/shard_$k/$label/windows.csv"
    [ -f "$f" ] || { say "missing $f"; fail=1; continue; }
    [ ! -e "$tmp/shards/shard_$k/$label/INCOMPLETE" ] || { say "shard $k of $label is INCOMPLETE"; fail=1; }
    [ "$(head -n1 "$f")" = "$header" ] || { say "$f: header differs from the unsharded run's"; fail=1; }
    bad="$(tail -n +2 "$f" | awk -F, -v n="$shards" -v k="$k" '$1 % n != k - 1 { print $1; exit }')"
    [ -z "$bad" ] || { say "$f: window $bad is not in shard $k/$shards"; fail=1; }
    tail -n +2 "$f" >>"$tmp/rows_$label.csv"
  done
  { echo "$header"; sort -s -t, -k1,1n "$tmp/rows_$label.csv"; } | drop_runtime >"$tmp/sharded_$label.csv"
  drop_runtime <"$ref" >"$tmp/unsharded_$label.csv"
  n_rows=$(($(wc -l <"$tmp/unsharded_$label.csv") - 1))
  if diff -u "$tmp/unsharded_$label.csv" "$tmp/sharded_$label.csv" >"$tmp/diff_$label.txt"; then
    say "$label: $n_rows rows (windows x methods) identical in $shards shards and unsharded (all columns but runtime_ms)"
  else
    say "$label: rows differ (unsharded vs shards, first lines of the diff):"
    head -n 20 "$tmp/diff_$label.txt" >&2
    fail=1
  fi
done
if "$celc" table "$tmp"/shards/shard_* -o "$tmp/merged" -q >"$tmp/log/table.out" 2>&1; then
  if cmp -s "$tmp/full/table.csv" "$tmp/merged.csv"; then
    say "celc table over the shards: table.csv identical to the unsharded batch's ($(($(wc -l <"$tmp/merged.csv") - 1)) rows)"
  else
    say "celc table over the shards differs from the unsharded table.csv:"
    diff "$tmp/full/table.csv" "$tmp/merged.csv" >&2
    fail=1
  fi
else
  say "celc table over the shards failed: $(tail -n 5 "$tmp/log/table.out")"
  fail=1
fi
[ "$fail" -eq 0 ] || die "sharded and unsharded results differ"
failed_phase=""
say "PASS: start-up $((t_up - t_begin)) s, unsharded $((t_full - t_up)) s, array $((t_array - t_full)) s, total $((SECONDS - t_begin)) s before shutdown"
