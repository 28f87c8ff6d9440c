#!/bin/bash
# The sweep's array job, then the merge once every task has ended. afterany, not afterok: a task
# whose shard holds a failed experiment exits 1, and the merge is what reports it.
set -euo pipefail
export SWEEP="${SWEEP:-sweep.toml}" OUT="${OUT:-/shared/armscope/sweep}"
mkdir -p "$OUT"
ARRAY=$(sbatch --parsable sweep.sbatch)
MERGE=$(sbatch --parsable --dependency="afterany:$ARRAY" --job-name=armscope-merge \
        --output="$OUT/merge.log" --wrap "armscope batch merge '$OUT'")
echo "array $ARRAY, merge $MERGE: the tables in $OUT/summary.md, the merge's report in $OUT/merge.log"
