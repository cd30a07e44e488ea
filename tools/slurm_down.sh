#!/usr/bin/env bash
# Stop the one-node SLURM that tools/slurm_up.sh started (slurmd, slurmctld, slurmdbd, MariaDB,
# munged), each by its own pid file; packages, configuration and the accounting database stay,
# so tools/slurm_up.sh starts it again in seconds.
set -uo pipefail
[ "$(id -u)" -eq 0 ] || { echo "slurm_down: must run as root" >&2; exit 2; }
stop() { # stop <name> <pidfile>
    local pid
    [ -s "$2" ] || return 0
    pid=$(cat "$2")
    kill -0 "$pid" 2>/dev/null || return 0
    kill "$pid"
    for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || { echo "slurm_down: $1 stopped"; return 0; }; sleep 0.2; done
    echo "slurm_down: $1 (pid $pid) did not stop in 20 s" >&2
    return 1
}
status=0
stop slurmd /run/slurm/slurmd.pid || status=1
stop slurmctld /run/slurm/slurmctld.pid || status=1
stop slurmdbd /run/slurm/slurmdbd.pid || status=1
if command -v mysqladmin >/dev/null && mysqladmin ping >/dev/null 2>&1; then
    mysqladmin shutdown && echo "slurm_down: MariaDB stopped" || status=1
fi
stop munged /run/munge/munged.pid || status=1
exit "$status"
