#!/usr/bin/env bash
# A weak-scaling job for a cluster: takes the rank count from the batch system's allocation,
# runs the lj-box gas with the spatial decomposition at 1, 2, 4, ... ranks up to it (n grows
# with the ranks) as one sweep under the launcher, then the communication benchmark at the
# full allocation. Results: results/<name>/results.json and results/<name>/mpi-bench.json (or
# under $OUT).
#
#   sbatch -n 64 --time=00:30:00 scripts/weak-mpi-job.sh       (Slurm: launches with srun)
#   qsub -l nodes=4:ppn=16 scripts/weak-mpi-job.sh              (PBS/Torque: mpirun)
#   RANKS=8 scripts/weak-mpi-job.sh                             (no batch system: mpirun)
#
# Submit from the repository root with a binary built beforehand:
#   cargo build --release --features mpi
# Settings (environment): RANKS (overrides the allocation), BASE_N (particles per rank,
# 100000), STEPS (200), WARMUP (20), DECOMP (domain; or "domain allgather"), LAUNCHER_ARGS
# (extra launcher arguments, e.g. "--bind-to none" for several threads per rank), THREADS (1),
# SRUN_MPI (srun's --mpi plugin, pmix; empty for the cluster's default), OUT (results).
# scripts/test.sh runs it under the one-node Slurm of scripts/slurm-local.sh.
#SBATCH --job-name=nbody-weak-mpi
set -euo pipefail
cd "${SLURM_SUBMIT_DIR:-${PBS_O_WORKDIR:-$(dirname "$0")/..}}"

ranks=${RANKS:-${SLURM_NTASKS:-${PBS_NP:-${NSLOTS:-${LSB_DJOB_NUMPROC:-}}}}}
if [ -z "$ranks" ] && [ -n "${PBS_NODEFILE:-}" ]; then
    ranks=$(wc -l <"$PBS_NODEFILE")
fi
if ! [[ "$ranks" =~ ^[1-9][0-9]*$ ]]; then
    echo "no rank count: submit through a batch system (sbatch -n N, qsub) or set RANKS=N" >&2
    exit 2
fi

read -r -a extra <<<"${LAUNCHER_ARGS:-}"
if [ -n "${SLURM_JOB_ID:-}" ]; then
    launcher=srun
    mpi_plugin=${SRUN_MPI-pmix}
    if [ -n "$mpi_plugin" ]; then
        extra=("--mpi=$mpi_plugin" ${extra[@]+"${extra[@]}"})
    fi
else
    launcher=mpirun
    if [ "$(id -u)" = 0 ]; then
        extra=(--allow-run-as-root ${extra[@]+"${extra[@]}"})
    fi
fi
bin=target/release/nbody-bench
if ! "$bin" mpi-bench --help >/dev/null 2>&1; then
    echo "$bin is missing; build it first: cargo build --release --features mpi" >&2
    exit 2
fi

# 1, 2, 4, ... up to the allocation, and the allocation itself.
series=()
for ((r = 1; r <= ranks; r *= 2)); do series+=("$r"); done
[ "${series[-1]}" = "$ranks" ] || series+=("$ranks")

quote() { printf '"%s", ' "$@" | sed 's/, $//'; }
read -r -a decomps <<<"${DECOMP:-domain}"
name="weak-mpi-${SLURM_JOB_ID:-${PBS_JOBID:-$(date +%Y%m%d-%H%M%S)}}"
name=${name//[^A-Za-z0-9._-]/-}
out=${OUT:-results}
mkdir -p "$out"
config="$out/$name.toml"
cat >"$config" <<EOF
# Written by scripts/weak-mpi-job.sh for an allocation of $ranks ranks.
name = "$name"
study = "weak"
scenarios = ["lj-box"]
kernels = ["cell-list"]
threads = [${THREADS:-1}]

[weak]
rule = "cost-model"
base_n = ${BASE_N:-100000}

[mpi]
launcher = "$launcher"
ranks = [$(IFS=,; echo "${series[*]}")]
args = [$( [ ${#extra[@]} -gt 0 ] && quote "${extra[@]}")]
decomp = [$(quote "${decomps[@]}")]
steps = ${STEPS:-200}
warmup_steps = ${WARMUP:-20}

[measure]
samples = 10
rounds = 2
EOF
echo "weak scaling over ranks ${series[*]} with $launcher; config $config"
"$bin" sweep --config "$config" --out "$out"
"$launcher" ${extra[@]+"${extra[@]}"} -n "$ranks" "$bin" mpi-bench --out "$out/$name/mpi-bench.json"
