#!/usr/bin/env bash
# A one-node SLURM cluster on this machine, with its accounting database, for the cluster
# tests (make test-cluster, docs/cluster.md):
#
#   tests/cluster/start_slurm.sh start   install what is missing, write the configuration,
#                                         start munge, MariaDB, slurmdbd, slurmctld, slurmd,
#                                         and wait until the node is idle and sacct answers
#   tests/cluster/start_slurm.sh stop    stop every daemon that `start` started
#   tests/cluster/start_slurm.sh preflight  only install what is missing (or say why not)
#
# It needs root (it installs Debian packages and starts system services) and Debian's package
# registry where a package is missing; without either it stops at once and says which.
# Its state and logs live in $AMONTONS_SLURM_DIR (default /tmp/amontons-slurm); its
# slurm.conf and slurmdbd.conf in /etc/slurm, where SLURM's commands look by default: the
# executor plugin's job steps drop every SLURM_* variable, SLURM_CONF included, before they
# call srun, so a configuration found only through SLURM_CONF fails inside the jobs ("srun:
# fatal: Could not establish a configuration source"). A slurm.conf there that this script
# did not write is left alone: it stops instead. `stop` removes the two files. Ran with
# Debian 12's SLURM 22.05.8, MariaDB 10.11 and munge 0.5.15 (`preflight` prints the versions
# it finds, `start` the ones it runs).
set -euo pipefail

DIR=${AMONTONS_SLURM_DIR:-/tmp/amontons-slurm}
CLUSTER=amontons
PARTITION=amontons
ACCOUNT=amontons-test
PACKAGES=(munge mariadb-server slurmdbd slurmctld slurmd slurm-client)
DB_PASSWORD=amontons-slurm
CONF=/etc/slurm
MARKER="# Written by tests/cluster/start_slurm.sh"

say() { echo "start_slurm.sh: $*" >&2; }
fail() {
    say "$*"
    exit 2
}

require_root() {
    [ "$(id -u)" = 0 ] || fail "needs root: it installs Debian's ${PACKAGES[*]} and starts \
them as system services; run it (make test-cluster) as root, as CI does"
}

install_missing_packages() {
    local missing=()
    for package in "${PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" ||
            missing+=("$package")
    done
    [ ${#missing[@]} = 0 ] && return
    command -v apt-get >/dev/null || fail "needs Debian's apt-get to install ${missing[*]}"
    say "installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -q >"$DIR/apt.log" 2>&1 ||
        fail "apt-get update failed (no package registry?): see $DIR/apt.log"
    apt-get install -y -q --no-install-recommends "${missing[@]}" >>"$DIR/apt.log" 2>&1 ||
        fail "apt-get install ${missing[*]} failed: see $DIR/apt.log"
}

write_slurm_conf() {
    local node cpus memory
    if [ -e "$CONF/slurm.conf" ] && ! grep -qx "$MARKER.*" "$CONF/slurm.conf"; then
        fail "$CONF/slurm.conf exists and was not written by this script: a SLURM is set up \
on this machine already; stopping rather than overwrite it"
    fi
    mkdir -p "$CONF"
    node=$(hostname -s)
    cpus=$(nproc)
    # slurmd drains a node that has less memory than configured: leave the system 5 %
    memory=$(awk '/MemTotal/ {print int($2 / 1024 * 0.95)}' /proc/meminfo)
    cat >"$CONF/slurm.conf" <<EOF
$MARKER: one node, one partition, accounting to slurmdbd
ClusterName=$CLUSTER
SlurmctldHost=$node(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/slurmctld.pid
SlurmdPidFile=$DIR/slurmd.pid
SlurmctldLogFile=$DIR/slurmctld.log
SlurmdLogFile=$DIR/slurmd.log
# no cgroups in a container: processes are tracked by their parent
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/linux
AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=127.0.0.1
# a job with an account the database does not know is refused, as on most clusters
AccountingStorageEnforce=associations
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
# finished jobs stay in slurmctld's memory for 5 min (the plugin warns when squeue could
# lose them sooner)
MinJobAge=300
KillWait=5
OverTimeLimit=0
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=$PARTITION Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
    cat >"$CONF/slurmdbd.conf" <<EOF
$MARKER
AuthType=auth/munge
DbdHost=localhost
DbdAddr=127.0.0.1
SlurmUser=root
PidFile=$DIR/slurmdbd.pid
LogFile=$DIR/slurmdbd.log
StorageType=accounting_storage/mysql
StorageHost=localhost
StorageUser=slurm
StoragePass=$DB_PASSWORD
StorageLoc=slurm_acct_db
EOF
    chmod 600 "$CONF/slurmdbd.conf"
}

# wait_for DESCRIPTION SECONDS COMMAND...: run COMMAND every half second until it succeeds
wait_for() {
    local what=$1 seconds=$2
    shift 2
    for _ in $(seq $((seconds * 2))); do
        "$@" >/dev/null 2>&1 && return
        sleep 0.5
    done
    fail "$what did not come up in $seconds s (logs in $DIR)"
}

node_is_idle() { sinfo -h -N -o %t | grep -qx idle; }

start_database() {
    if ! mariadb-admin ping >/dev/null 2>&1; then
        /etc/init.d/mariadb start >"$DIR/mariadb.start.log" 2>&1 ||
            fail "MariaDB did not start: see $DIR/mariadb.start.log"
        touch "$DIR/started-mariadb"
    fi
    mariadb -e "CREATE USER IF NOT EXISTS 'slurm'@'localhost' IDENTIFIED BY '$DB_PASSWORD';
        GRANT ALL ON slurm_acct_db.* TO 'slurm'@'localhost';"
}

start_munge() {
    if ! munge -n </dev/null >/dev/null 2>&1; then
        [ -s /etc/munge/munge.key ] || mungekey --create
        /etc/init.d/munge start >"$DIR/munge.start.log" 2>&1 ||
            fail "munge did not start: see $DIR/munge.start.log"
        touch "$DIR/started-munge"
    fi
    wait_for munge 10 sh -c 'munge -n </dev/null | unmunge'
}

add_account() {
    # sacctmgr -i refuses nothing twice: an existing entity is only a message
    sacctmgr -i add cluster "$CLUSTER" >/dev/null || true
    sacctmgr -i add account "$ACCOUNT" Cluster="$CLUSTER" \
        Description="amontons cluster tests" Organization=amontons >/dev/null || true
    sacctmgr -i add user "$(id -un)" Account="$ACCOUNT" DefaultAccount="$ACCOUNT" \
        Cluster="$CLUSTER" >/dev/null || true
    sacctmgr -n -P show association cluster="$CLUSTER" account="$ACCOUNT" user="$(id -un)" |
        grep -q "$ACCOUNT" || fail "sacctmgr did not record account $ACCOUNT"
}

start() {
    require_root
    mkdir -p "$DIR/state" "$DIR/spool"
    # a cluster left running by an earlier start (a test killed before its stop) goes first
    stop_daemons
    install_missing_packages
    write_slurm_conf
    start_munge
    start_database
    slurmdbd
    wait_for slurmdbd 30 sacctmgr -n show cluster
    add_account
    slurmctld
    slurmd
    wait_for "the node $(hostname -s), idle," 60 node_is_idle
    wait_for sacct 30 sacct -n -X
    say "running: $(sinfo -V), $(mariadb --version | cut -d, -f1), $(munge --version 2>&1 |
        cut -d' ' -f1); partition $PARTITION, account $ACCOUNT"
}

stop_pid_file() {
    local file=$1
    [ -s "$file" ] || return 0
    local pid
    pid=$(cat "$file")
    kill "$pid" 2>/dev/null || return 0
    for _ in $(seq 40); do
        kill -0 "$pid" 2>/dev/null || return 0
        sleep 0.25
    done
    kill -9 "$pid" 2>/dev/null || true
}

stop_daemons() {
    # jobs first, so that no slurmstepd outlives its daemon
    if [ -s "$DIR/slurmctld.pid" ]; then scancel --user "$(id -un)" 2>/dev/null || true; fi
    for daemon in slurmd slurmctld slurmdbd; do
        stop_pid_file "$DIR/$daemon.pid"
    done
}

stop() {
    stop_daemons
    if [ -e "$DIR/started-mariadb" ]; then
        /etc/init.d/mariadb stop >/dev/null 2>&1 || true
        rm -f "$DIR/started-mariadb"
    fi
    if [ -e "$DIR/started-munge" ]; then
        /etc/init.d/munge stop >/dev/null 2>&1 || true
        rm -f "$DIR/started-munge"
    fi
    for file in slurm.conf slurmdbd.conf; do
        if grep -qx "$MARKER.*" "$CONF/$file" 2>/dev/null; then rm -f "$CONF/$file"; fi
    done
    say "stopped"
}

case "${1:-}" in
preflight)
    require_root
    mkdir -p "$DIR"
    install_missing_packages
    say "ready: $(dpkg-query -W -f='${Package} ${Version}, ' "${PACKAGES[@]}")"
    ;;
start) start ;;
stop) stop ;;
*) fail "usage: $0 preflight|start|stop" ;;
esac
