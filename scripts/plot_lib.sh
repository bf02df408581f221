# shellcheck shell=bash
# What plot scripts share beyond lib.sh (sourced here: a plot script sources only this):
# plot_setup and plot_panels for the paper figures (plot_cof.sh, plot_kinematics.sh,
# plot_fig2.sh); plot_file_option and plot_file_setup for the figures of one output file
# (plot_mfd.sh, plot_slip_map.sh, plot_ruptures.sh).  Sourced, not run.

# shellcheck source=lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

# plot_setup MIN_ARGS "$@": the options every paper figure takes, --format F and --block I, up
# to the first argument that is none; -h/--help prints the script's help; a bad or unknown
# option or fewer than MIN_ARGS arguments is a usage error (exit 2).  Sets PLOT_TERMINAL (the
# cairo terminal, noenhanced), PLOT_BLOCK, PLOT_ARGS (the arguments after the options), and
# bksim (the binary) and tmp (a temporary directory, removed at exit).
plot_setup() {
    local min=$1 format=png
    shift
    PLOT_BLOCK=0
    while [ $# -gt 0 ]; do
        case $1 in
            --format|--block)
                bk_need_value $# "$1"
                if [ "$1" = --format ]; then format=$2; else PLOT_BLOCK=$2; fi
                shift 2 ;;
            -h|--help) bk_help ;;
            -*) bk_usage "unknown option '$1'" ;;
            *) break ;;
        esac
    done
    bk_terminal PLOT_TERMINAL "$format"
    PLOT_TERMINAL+=" noenhanced"
    bk_check_whole --block "$PLOT_BLOCK" "a block index" 0
    [ $# -ge "$min" ] || bk_usage
    PLOT_ARGS=("$@")
    bk_find_bksim bksim
    bk_temp_dir tmp
}

# plot_panels OUT TITLE ROWS MARGIN: the start of a gnuplot script drawing ROWS panels stacked
# in one column to OUT (PLOT_TERMINAL), under TITLE: grids, legends outside on the right, the
# same left and right margins for every panel (so that they line up whatever their legends'
# widths), MARGIN (a fraction of the panel) above and below the data, and time zoomed to
# $XRANGE (lo:hi in s) when set.  The panels and "unset multiplot" follow.
plot_panels() {
    cat <<GP
set terminal $PLOT_TERMINAL
set output '$1'
set multiplot layout $3,1 title '$2'
set grid
${XRANGE:+set xrange [$XRANGE]}
set offsets 0, 0, graph $4, graph $4
set key outside right top
# Fixed margins: panels line up whatever their legends' widths.
set lmargin at screen 0.09
set rmargin at screen 0.80
GP
}

PLOT_FORMAT=png PLOT_OUTDIR="" PLOT_FILE=""
# plot_file_option "$@": one option or argument of a figure of FILE.h5: --format F (or
# --format=F), -o/--output OUTDIR, -h/--help, or FILE.h5 itself (once); anything else is a
# usage error.  Sets PLOT_FORMAT, PLOT_OUTDIR or PLOT_FILE, and PLOT_SHIFT (how many arguments
# it took).
plot_file_option() {
    PLOT_SHIFT=1
    case $1 in
        --format) bk_need_value $# "$1"; PLOT_FORMAT=$2; PLOT_SHIFT=2 ;;
        --format=*) PLOT_FORMAT=${1#--format=} ;;
        -o|--output) bk_need_value $# "$1"; PLOT_OUTDIR=$2; PLOT_SHIFT=2 ;;
        -h|--help) bk_help ;;
        -*) bk_usage "unknown option '$1'" ;;
        *) [ -z "$PLOT_FILE" ] || bk_usage "unexpected argument '$1'"
           PLOT_FILE=$1 ;;
    esac
}

# plot_file_setup: after the options: FILE.h5 given (else a usage error), the format known
# (PLOT_TERMINAL, noenhanced), FILE readable, gnuplot and bksim there.  Sets file, format,
# terminal, bksim, outdir (default FILE's directory, created), stem (FILE's name without .h5
# and .part) and tmp (a temporary directory, removed at exit, as is a figure plot_draw left
# half-drawn).
plot_file_setup() {
    [ -n "$PLOT_FILE" ] || bk_usage "missing FILE.h5"
    file=$PLOT_FILE format=$PLOT_FORMAT
    bk_terminal terminal "$format"
    terminal+=" noenhanced"
    bk_need_file "$file"
    bk_need_command gnuplot gnuplot-nox
    bk_find_bksim bksim
    outdir=${PLOT_OUTDIR:-$(dirname "$file")}
    mkdir -p "$outdir" || bk_fail 1 "$outdir: cannot create the output directory"
    stem=$(basename "$file"); stem=${stem%.part}; stem=${stem%.h5}
    bk_temp_dir tmp
    PLOT_PARTIAL=""
    bk_at_exit '[ -z "$PLOT_PARTIAL" ] || rm -f "$PLOT_PARTIAL"'
}

# plot_draw OUT: the gnuplot script on stdin (after plot_file_setup: its terminal, UTF-8)
# drawn to OUT through a hidden file beside it, renamed when gnuplot succeeded, so that a
# failed figure never leaves a half-written OUT; OUT is appended to the array outputs.
plot_draw() {
    PLOT_PARTIAL=$(mktemp "$outdir/.$(basename "$1").XXXXXX") || bk_fail 1 "$outdir: cannot write there"
    { echo "set encoding utf8"; echo "set terminal $terminal"; echo "set output '$(bk_gp_quote "$PLOT_PARTIAL")'"; cat; } |
        gnuplot 2> "$tmp/gp.err" || bk_fail 1 "gnuplot failed drawing $1: $(cat "$tmp/gp.err")"
    chmod "$(printf %o $((0666 & ~0$(umask))))" "$PLOT_PARTIAL" || true
    mv -f "$PLOT_PARTIAL" "$1" || bk_fail 1 "cannot rename $PLOT_PARTIAL to $1"
    PLOT_PARTIAL=""
    outputs+=("$1")
}

# plot_file_shape FILE: the chain's length and the lattice's shape from bksim info (its exit
# status says whether the run finished, which does not matter here): sets info (what bksim
# info printed, for the caller's own questions), n_blocks (empty when
# info gives none: another program's catalog), rows and cols ("lattice R x C blocks ...", or no
# such line for a chain, one row).  A lattice line that does not read so is an error, never a
# chain drawn in its place.
plot_file_shape() {
    local shape
    info=$({ "$bksim" info "$1" 2>/dev/null || true; })
    n_blocks=$(awk '$1 == "n_blocks" {print $2; exit}' <<<"$info")
    [[ ${n_blocks:-} =~ ^[0-9]+$ ]] || { n_blocks="" rows=1 cols=""; return 0; }
    shape=$(awk '$1 == "lattice" {
            print ($2 ~ /^[0-9]+$/ && $3 == "x" && $4 ~ /^[0-9]+$/) ? $2 " " $4 : "unreadable"; exit
        }' <<<"$info")
    [ "$shape" != unreadable ] || bk_fail 1 "$1: cannot read the lattice's shape from bksim info: $(grep '^lattice' <<<"$info")"
    read -r rows cols <<<"${shape:-1 $n_blocks}"
    [ "$((rows * cols))" -eq "$n_blocks" ] || bk_fail 1 "$1: a $rows x $cols lattice of $n_blocks blocks"
}

# plot_require_sample_rows FILE WHAT: refuse (exit 1) a run without sample rows between t = 0
# and its end (as [output] interval = 0 writes): nothing of block PLOT_BLOCK's WHAT between
# its transitions is in it, and a line through the rows it has (t = 0, the end, transition
# instants) would draw slips that did not happen.
plot_require_sample_rows() {
    [ "$(bk_sample_rows "$1")" -le 2 ] || return 0
    bk_fail 1 "$1 has no sample rows between t = 0 and its end (as with [output] interval = 0): nothing" \
            "of block $PLOT_BLOCK's $2 between its transitions is in it, and a line through the rows it has" \
            "would draw slips that did not happen; run it with [output] interval > 0 (bksim check says" \
            "what the rows weigh), or list the transitions with bksim export $1 --transitions"
}
