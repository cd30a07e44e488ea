#!/usr/bin/env bash
# Boot a one-node SLURM on this Debian machine, as root, so that the cluster profile
# (workflow/profiles/cluster) can be run for real: by tests/test_slurm.py and by a developer who
# wants to try it (docs/cluster.md). Debian's packages (slurm-wlm, slurmdbd, mariadb-server,
# munge); no systemd needed: each daemon is started directly and found again by its pid file.
#
#   tools/slurm_up.sh      install if missing, then start what is not running (idempotent)
#   tools/slurm_down.sh    stop the daemons this script started (the packages stay)
#
# The cluster: ClusterName physgs, one node (this host, its CPUs and 90% of its memory as
# RealMemory), one partition "cpu" (default, no time limit), one account "physgs" (the invoking
# user's default account), accounting through slurmdbd on MariaDB (sacct works; per-job CPU time
# and MaxRSS are gathered every second, so the plugin's --slurm-efficiency-report has numbers;
# job comments are stored, the plugin puts the rule name there).
# MessageTimeout=2 (Slurm's default is 10): the SLURM executor plugin runs `scontrol show config`
# whenever Snakemake starts, every command and every dry run; once these packages are installed and
# the daemons are down (after tools/slurm_down.sh, or a reboot) scontrol retries the controller for
# MessageTimeout - 1 seconds, so each `snakemake` call slept 9 s; now 1 s. Round trips to this
# one-node controller take milliseconds.
# Exit status: 0 booted (sinfo shows the node idle or busy); 2 cannot boot here (not root, no
# apt-get and no slurm): the message says why; 1 a daemon did not come up (its log is named).
set -euo pipefail

CLUSTER=physgs
ACCOUNT=physgs
PARTITION=cpu
RUN=/run/slurm
LOG=/var/log/slurm

die() { echo "slurm_up: $2" >&2; exit "$1"; }

[ "$(id -u)" -eq 0 ] || die 2 "must run as root (it installs packages and starts daemons)"
if ! command -v slurmctld >/dev/null || ! command -v slurmdbd >/dev/null \
    || ! command -v mariadbd >/dev/null || ! command -v munged >/dev/null; then
    command -v apt-get >/dev/null || die 2 "SLURM is not installed and there is no apt-get"
    echo "slurm_up: installing slurm-wlm slurmdbd mariadb-server munge (about a minute)"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq || die 2 "apt-get update failed (no network or no package source?)"
    apt-get install -y -qq slurm-wlm slurmdbd mariadb-server munge >/dev/null \
        || die 2 "apt-get install slurm-wlm slurmdbd mariadb-server munge failed"
fi

# running <pidfile>: the daemon whose pid the file names is alive
running() { [ -s "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }
# wait_for <seconds> <command...>: poll until the command succeeds
wait_for() {
    local n=$1; shift
    for _ in $(seq "$((n * 5))"); do "$@" >/dev/null 2>&1 && return 0; sleep 0.2; done
    return 1
}

host=$(hostname -s)
getent hosts "$host" >/dev/null || die 2 "this host's name '$host' does not resolve (/etc/hosts)"
cpus=$(nproc)
mem=$(($(free -m | awk '/^Mem:/{print $2}') * 9 / 10))

# ---- munge: the key, then munged ---------------------------------------------------------------
mkdir -p /etc/munge /var/lib/munge /var/log/munge /run/munge
[ -s /etc/munge/munge.key ] || dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key 2>/dev/null
chown -R munge:munge /etc/munge /var/lib/munge /var/log/munge /run/munge
chmod 400 /etc/munge/munge.key
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
    runuser -u munge -- /usr/sbin/munged --force
    wait_for 10 sh -c 'munge -n | unmunge' || die 1 "munged did not start (/var/log/munge/munged.log)"
fi

# ---- MariaDB: the accounting database -----------------------------------------------------------
mkdir -p /run/mysqld && chown mysql:mysql /run/mysqld
if ! mysqladmin ping >/dev/null 2>&1; then
    (setsid mysqld_safe >/dev/null 2>&1 &)
    wait_for 30 mysqladmin ping || die 1 "MariaDB did not start (/var/log/mysql/error.log)"
fi
mysql -e "CREATE DATABASE IF NOT EXISTS slurm_acct_db;
CREATE USER IF NOT EXISTS 'slurm'@'localhost' IDENTIFIED BY 'slurmpw';
GRANT ALL ON slurm_acct_db.* TO 'slurm'@'localhost'; FLUSH PRIVILEGES;"

# ---- configuration: rewritten only when it changed (then the daemons restart) ------------------
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd "$LOG" "$RUN"
chown -R slurm:slurm /var/spool/slurmctld "$LOG" "$RUN"
slurm_conf=$(
    cat <<CONF
# written by physgs tools/slurm_up.sh
ClusterName=$CLUSTER
SlurmctldHost=$host
SlurmUser=slurm
AuthType=auth/munge
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=$RUN/slurmctld.pid
SlurmdPidFile=$RUN/slurmd.pid
SlurmctldLogFile=$LOG/slurmctld.log
SlurmdLogFile=$LOG/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MpiDefault=none
AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=localhost
AccountingStorageEnforce=associations
AccountingStoreFlags=job_comment
JobAcctGatherType=jobacct_gather/linux
JobAcctGatherFrequency=task=1
JobCompType=jobcomp/none
MinJobAge=600
MessageTimeout=2
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=$PARTITION Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
)
dbd_conf=$(
    cat <<CONF
# written by physgs tools/slurm_up.sh
AuthType=auth/munge
DbdHost=localhost
SlurmUser=slurm
PidFile=$RUN/slurmdbd.pid
LogFile=$LOG/slurmdbd.log
StorageType=accounting_storage/mysql
StorageHost=localhost
StorageUser=slurm
StoragePass=slurmpw
StorageLoc=slurm_acct_db
CONF
)
changed=0
if [ "$(cat /etc/slurm/slurm.conf 2>/dev/null)" != "$slurm_conf" ]; then
    printf '%s\n' "$slurm_conf" >/etc/slurm/slurm.conf
    changed=1
fi
if [ "$(cat /etc/slurm/slurmdbd.conf 2>/dev/null)" != "$dbd_conf" ]; then
    printf '%s\n' "$dbd_conf" >/etc/slurm/slurmdbd.conf
    changed=1
fi
chown slurm:slurm /etc/slurm/slurmdbd.conf
chmod 600 /etc/slurm/slurmdbd.conf
if [ "$changed" = 1 ]; then # a daemon started from the old configuration restarts
    for d in slurmd slurmctld slurmdbd; do
        if running "$RUN/$d.pid"; then
            kill "$(cat "$RUN/$d.pid")"
            wait_for 20 sh -c "! kill -0 $(cat "$RUN/$d.pid") 2>/dev/null" || die 1 "$d did not stop"
        fi
    done
fi

# ---- the daemons, in order: slurmdbd, the cluster's accounts, slurmctld, slurmd -----------------
if ! running "$RUN/slurmdbd.pid"; then
    /usr/sbin/slurmdbd
    wait_for 20 sacctmgr -n list cluster || die 1 "slurmdbd did not start ($LOG/slurmdbd.log)"
fi
sacctmgr -n list cluster format=cluster | grep -qw "$CLUSTER" || sacctmgr -i add cluster "$CLUSTER" >/dev/null
sacctmgr -n list account format=account | grep -qw "$ACCOUNT" \
    || sacctmgr -i add account "$ACCOUNT" Description=physgs Organization=physgs >/dev/null
user=${SUDO_USER:-$(id -un)}
sacctmgr -n list assoc user="$user" account="$ACCOUNT" format=user | grep -qw "$user" \
    || sacctmgr -i add user "$user" Account="$ACCOUNT" >/dev/null
sacctmgr -n list user "$user" format=defaultaccount | grep -qw "$ACCOUNT" \
    || sacctmgr -i modify user "$user" set DefaultAccount="$ACCOUNT" >/dev/null
if ! running "$RUN/slurmctld.pid"; then
    /usr/sbin/slurmctld
    wait_for 20 scontrol ping || die 1 "slurmctld did not start ($LOG/slurmctld.log)"
fi
if ! running "$RUN/slurmd.pid"; then
    /usr/sbin/slurmd
fi
node_up() { sinfo -h -n "$host" -o %T | grep -qE '^(idle|mixed|allocated)'; }
if ! wait_for 30 node_up; then
    scontrol update NodeName="$host" State=RESUME >/dev/null 2>&1 || true
    wait_for 10 node_up || die 1 "node $host is not up: $(sinfo -h -o '%T %E') ($LOG/slurmd.log)"
fi
sinfo -o '%P %a %l %D %c %m %T %N'
