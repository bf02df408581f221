# shellcheck shell=bash
# Shared by scripts/sweep.sh, scripts/sweep_point.sh and scripts/slurm/*, on top of lib.sh
# (sourced here): the grid plan and the end-of-sweep report.  Every message starts "sweep: ",
# and every failure exits 2 (bad usage, as sweep.sh documents), a missing bksim too.
# Sourced, not run; the SLURM jobs source it by the scripts directory submit.sh gives them.

# shellcheck source=lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
BK_PROG=sweep

# A value as a file-name part: characters outside [A-Za-z0-9._+-] become '_'.
sweep_clean() {
    printf '%s' "$1" | tr -c 'A-Za-z0-9._+-' '_'
}

# sweep_plan DIR BASE.ini KEY=V1,V2 ...: check the arguments, write DIR/base.ini and
# DIR/points.tsv (point, then one column per key), or check that a rerun gives the same
# ones.  An empty DIR is out/sweeps/<BASE name>.  Sets SWEEP_DIR and SWEEP_POINTS.  Point
# names join the swept keys' key=value (a key with one value is fixed and left out of the
# name) with ','.
sweep_plan() {
    local dir=$1
    shift
    [ $# -ge 1 ] || bk_usage "missing BASE.ini"
    local base=$1
    shift
    [ -n "$dir" ] || dir=out/sweeps/$(basename "$base" .ini)
    SWEEP_DIR=$dir
    bk_need_file "$base" "config file" 2
    local -a keys=() lists=()
    local arg key values
    for arg in "$@"; do
        [[ $arg == *=* ]] || bk_fail 2 "'$arg' is not KEY=V1,V2,... (e.g. friction.mu_d=0.1,0.2)"
        key=${arg%%=*}
        values=${arg#*=}
        [[ $key =~ ^[A-Za-z_]+(\.[0-9]+)?\.[A-Za-z0-9_]+$ ]] ||
            bk_fail 2 "'$key' is not a section.key (e.g. friction.mu_d, block.3.mass)"
        [ -n "$values" ] && [[ $values != *,,* && $values != ,* && $values != *, ]] ||
            bk_fail 2 "$key: every value must be non-empty, got '$values'"
        [[ $values != *$'\t'* && $values != *$'\n'* ]] || bk_fail 2 "$key: a value holds a tab or newline"
        local k
        for k in "${keys[@]}"; do
            [ "$k" != "$key" ] || bk_fail 2 "$key is given twice: list all its values in one argument"
        done
        keys+=("$key")
        lists+=("$values")
    done
    # The Cartesian product, first key slowest: each row is "name<TAB>v1<TAB>v2...".
    local -a rows=("") names=("")
    local i j row value part swept
    for i in "${!keys[@]}"; do
        local -a vals new_rows=() new_names=()
        IFS=, read -r -a vals <<< "${lists[$i]}"
        swept=$([ ${#vals[@]} -gt 1 ] && echo 1 || echo 0)
        for j in "${!rows[@]}"; do
            for value in "${vals[@]}"; do
                new_rows+=("${rows[$j]}"$'\t'"$value")
                part=""
                [ "$swept" = 1 ] && part="${keys[$i]}=$(sweep_clean "$value")"
                if [ -n "$part" ] && [ -n "${names[$j]}" ]; then
                    new_names+=("${names[$j]},$part")
                else
                    new_names+=("${names[$j]}$part")
                fi
            done
        done
        rows=("${new_rows[@]}")
        names=("${new_names[@]}")
    done
    local plan header
    header=point
    for key in "${keys[@]}"; do header+=$'\t'$key; done
    plan=$(
        echo "$header"
        for j in "${!rows[@]}"; do
            printf '%s%s\n' "${names[$j]:-base}" "${rows[$j]}"
        done
    )
    local dup
    dup=$(tail -n +2 <<< "$plan" | cut -f1 | sort | uniq -d | head -1)
    [ -z "$dup" ] || bk_fail 2 "two points share the name '$dup' (a value repeated, or values that differ only in characters outside [A-Za-z0-9._+-])"
    awk -F'\t' 'NR > 1 && length($1) > 200 {exit 1}' <<< "$plan" ||
        bk_fail 2 "a point's name would pass 200 characters: sweep fewer keys at once"

    mkdir -p "$dir/logs" || bk_fail 2 "$dir: cannot create"
    if [ -e "$dir/base.ini" ]; then
        cmp -s "$base" "$dir/base.ini" ||
            bk_fail 2 "$dir holds a sweep of another config than $base: use another -o DIR"
    fi
    if [ -e "$dir/points.tsv" ]; then
        [ "$plan" = "$(cat "$dir/points.tsv")" ] ||
            bk_fail 2 "$dir holds a sweep of another grid (see $dir/points.tsv): use another -o DIR"
    fi
    if [ ! -e "$dir/base.ini" ] || [ ! -e "$dir/points.tsv" ]; then
        # The first point is checked before anything is written: a typo in a key fails here.
        local bksim first
        local -a sets=()
        bk_find_bksim bksim 2
        first=$(sed -n 2p <<< "$plan")
        IFS=$'\t' read -r -a vals <<< "$first"
        for i in "${!keys[@]}"; do sets+=(--set "${keys[$i]}=${vals[$((i + 1))]}"); done
        "$bksim" check "$base" "${sets[@]}" > /dev/null || bk_fail 2 "the first point's config is refused (above)"
        cp "$base" "$dir/base.ini.tmp" && mv "$dir/base.ini.tmp" "$dir/base.ini"
        echo "$plan" > "$dir/points.tsv.tmp" && mv "$dir/points.tsv.tmp" "$dir/points.tsv"
    fi
    SWEEP_POINTS=$((${#rows[@]}))
}

# After the runs: how many points finished, the summary, a line in sweep.log.  Returns 1
# when a point has no finished output.
sweep_report() {
    local dir=$1 name total=0 finished=0 bksim
    local -a missing=()
    while IFS= read -r name; do
        total=$((total + 1))
        if [ -e "$dir/$name.h5" ]; then finished=$((finished + 1)); else missing+=("$name"); fi
    done < <(tail -n +2 "$dir/points.tsv" | cut -f1)
    local line="$(date '+%F %T')	sweep	$finished of $total points finished"
    [ ${#missing[@]} -eq 0 ] || line+="; not finished: ${missing[*]}"
    echo "$line" >> "$dir/sweep.log"
    echo "sweep: $finished of $total points finished in $dir" >&2
    if [ "$finished" -gt 0 ]; then
        bk_find_bksim bksim 2
        "$bksim" summary "$dir" >&2 || return 1
    fi
    if [ ${#missing[@]} -ne 0 ]; then
        echo "sweep: ${#missing[@]} points failed or did not run (why: $dir/sweep.log, $dir/logs/)" >&2
        return 1
    fi
}
