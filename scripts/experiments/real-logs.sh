# Sourced by the scripts that score denoisers on the real logs (denoise-real.sh,
# denoise-variants.sh): the paths, the tools they need, and a log name's rawlog.
# Sets root, data (KFD_DATASETS_DIR or ../shared/datasets), bin (build/apps) and all_logs.
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
data="${KFD_DATASETS_DIR:-$root/../shared/datasets}"
bin="$root/build/apps"
all_logs=(fr079 aces intel mit-csail mines-exp1 mines-exp2)
for t in kfd-inject kfd-denoise-eval; do
  [ -x "$bin/$t" ] || { echo "build $t first (bash scripts/demo.sh)" >&2; exit 1; }
done
# log_path NAME: the rawlog of a log name (fr079, aces, intel, mit-csail, mines-exp1, mines-exp2).
log_path() {
  case $1 in
    mines-exp1) echo "$data/mines-urg/exp1.rawlog" ;;
    mines-exp2) echo "$data/mines-urg/exp2.rawlog" ;;
    *) echo "$data/$1/$1.rawlog" ;;
  esac
}
