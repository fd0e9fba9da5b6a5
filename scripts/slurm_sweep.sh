#!/bin/bash
# A Slurm job for an rfem sweep across nodes: rank 0 hands out the points, every other rank runs
# them one thread each (README, "Studies beyond one machine"). Submit with
#   sbatch scripts/slurm_sweep.sh cases/sweeps/paper_n_T.toml
# A job that hits its time limit (Slurm sends SIGTERM first) leaves a valid index; submitting the
# same job again runs only the points that did not finish.
#SBATCH --job-name=rfem-sweep
#SBATCH --ntasks=65                 # 64 workers + the coordinator
#SBATCH --cpus-per-task=1
#SBATCH --time=02:00:00
#SBATCH --signal=TERM@120           # time to end the running points cleanly
set -euo pipefail
export OMP_NUM_THREADS=1
mpirun rfem sweep "$1" -q   # OpenMPI's mpirun starts one rank per task of the allocation
