# shellcheck shell=bash
# What every script under scripts/ shares, sourced first thing (not run):
#     source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
# Sourcing it only defines the names below: it needs no build (scripts/quickstart.sh sources
# it on a fresh machine), and bksim is looked for when a script asks (bk_find_bksim).
#   BK_SCRIPTS, BK_REPO  this directory and the repository above it, absolute
#   BK_SCRIPT            the running script, absolute (its help is read from it)
#   BK_PROG              the name before every message (the script's; a script may set another)
# Helpers of one topic live beside it and source it themselves (a script that needs them
# sources only the topic's file): plot_lib.sh (what the plot scripts share beyond this) and
# sweep_lib.sh (a sweep's plan and report).

[ -z "${BK_LIB_LOADED:-}" ] || return 0
BK_LIB_LOADED=1
BK_SCRIPTS=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
BK_REPO=$(dirname "$BK_SCRIPTS")
if BK_SCRIPT=$(cd "$(dirname "$0")" 2> /dev/null && pwd); then BK_SCRIPT+=/$(basename "$0"); else BK_SCRIPT=$0; fi
BK_PROG=$(basename "$0")
# Where the script was started: a relative $BKSIM names a file from there, even after a cd.
BK_START_DIR=$PWD

# --- messages, help and exits -----------------------------------------------------------------

# bk_fail STATUS MESSAGE...: "prog: MESSAGE" on stderr, then exit STATUS.
bk_fail() {
    local status=$1
    shift
    echo "$BK_PROG: $*" >&2
    exit "$status"
}

# bk_warn MESSAGE...: "prog: MESSAGE" on stderr, and go on.
bk_warn() {
    echo "$BK_PROG: $*" >&2
}

# The script's help: its leading comment block, the "#" and "# ..." lines after the shebang up
# to the first other line, without their "# ".
bk_help_text() {
    awk 'NR == 1 && /^#!/ { next } /^#( |$)/ { sub(/^# ?/, ""); print; next } { exit }' "$BK_SCRIPT"
}

# -h/--help: the help on stdout, exit 0.
bk_help() {
    bk_help_text
    exit 0
}

# bk_usage [MESSAGE...]: a usage error: "prog: MESSAGE" when given, then the help's "usage:"
# line and the lines that continue it (indented past "usage: ") on stderr; exit 2.
bk_usage() {
    [ $# -eq 0 ] || echo "$BK_PROG: $*" >&2
    bk_help_text | awk '/^usage:/ { u = 1; print; next } u && /^       / { print; next } { u = 0 }' >&2
    exit 2
}

# --- checks on what a script is given -----------------------------------------------------------

# bk_need_value COUNT OPTION [WHAT]: OPTION takes a value (COUNT is $# where OPTION is $1):
# without one, a usage error "OPTION needs WHAT" (default "a value").
bk_need_value() {
    [ "$1" -ge 2 ] || bk_usage "$2 needs ${3:-a value}"
}

# bk_check_whole OPTION VALUE WHAT MIN: VALUE is a whole number >= MIN (0 or 1; written
# without leading zeros when MIN is 1), else a usage error "OPTION needs WHAT >= MIN, got 'VALUE'".
bk_check_whole() {
    local pattern='^[0-9]+$'
    [ "$4" = 0 ] || pattern='^[1-9][0-9]*$'
    [[ $2 =~ $pattern ]] || bk_usage "$1 needs $3 >= $4, got '$2'"
}

# bk_need_file PATH [WHAT [STATUS]]: PATH is a regular file this script can read, else fail
# with STATUS (default 1): "PATH: no such WHAT" (default "file"), "PATH: not a regular file"
# or "PATH: cannot be read".
bk_need_file() {
    local what=${2:-file} status=${3:-1}
    [ -e "$1" ] || bk_fail "$status" "$1: no such $what"
    [ -f "$1" ] || bk_fail "$status" "$1: not a regular file"
    [ -r "$1" ] || bk_fail "$status" "$1: cannot be read"
}

# bk_need_command COMMAND PACKAGE: COMMAND can be run, else fail (1): "needs COMMAND (Debian
# package PACKAGE)".
bk_need_command() {
    command -v "$1" > /dev/null 2>&1 || bk_fail 1 "needs $1 (Debian package $2)"
}

# bk_missing_packages PACKAGE...: those of the Debian packages that are not installed, one a line.
bk_missing_packages() {
    local package
    for package in "$@"; do
        dpkg-query -W -f='${Status}' "$package" 2> /dev/null | grep -q "install ok installed" ||
            echo "$package"
    done
}

# The functions that set a variable VAR (printf -v) name their own locals _bk_*, so that any
# other name works as VAR.

# --- the bksim binary ---------------------------------------------------------------------------

# bk_find_bksim VAR [STATUS]: the bksim binary, as an absolute path, into VAR: $BKSIM when set
# (a name without "/" is looked up on PATH, a relative path is taken from where the script
# started; either must be an executable file), else the repository's own ./bksim, else bksim on
# PATH.  Fails with STATUS (default 1) when there is none.
bk_find_bksim() {
    local _bk_status=${2:-1} _bk_found=""
    if [ -n "${BKSIM:-}" ]; then
        case $BKSIM in
            /*) _bk_found=$BKSIM ;;
            */*) _bk_found=$BK_START_DIR/$BKSIM ;;
            *) _bk_found=$(command -v -- "$BKSIM") || _bk_found="" ;;
        esac
        [ -n "$_bk_found" ] && [ -f "$_bk_found" ] && [ -x "$_bk_found" ] ||
            bk_fail "$_bk_status" "BKSIM=$BKSIM is not an executable"
    elif [ -x "$BK_REPO/bksim" ]; then
        _bk_found=$BK_REPO/bksim
    else
        _bk_found=$(command -v bksim) ||
            bk_fail "$_bk_status" "no bksim in $BK_REPO nor on PATH: build it (make) or set BKSIM"
    fi
    printf -v "$1" '%s/%s' "$(cd "$(dirname "$_bk_found")" && pwd)" "$(basename "$_bk_found")"
}

# --- temporary files ----------------------------------------------------------------------------

BK_AT_EXIT=()
# bk_at_exit COMMAND: run COMMAND (a line of shell) when the script exits, after the ones given
# before; the script's exit status stays its own.
bk_at_exit() {
    BK_AT_EXIT+=("$1")
    trap bk_run_at_exit EXIT
}
bk_run_at_exit() {
    local command
    for command in "${BK_AT_EXIT[@]}"; do eval "$command" || true; done
}

# bk_temp_dir VAR: a new temporary directory into VAR, removed with its contents at exit.
# bk_sample_rows FILE: the regular sample rows of a run's output (not the rows at transition
# instants), with bksim set (bk_find_bksim).  Two (t = 0 and t_end) means [output] interval = 0:
# nothing between its transitions is in the file.
bk_sample_rows() {
    "$bksim" export "$1" --datasets event 2> /dev/null | awk '!/^#/ && $1 == 0 {n++} END {print n+0}'
}

bk_temp_dir() {
    local _bk_dir
    _bk_dir=$(mktemp -d) || bk_fail 1 "cannot create a temporary directory"
    printf -v "$1" '%s' "$_bk_dir"
    bk_at_exit "rm -rf $(printf '%q' "$_bk_dir")"
}

# --- gnuplot ------------------------------------------------------------------------------------

# bk_terminal VAR FORMAT: gnuplot's cairo terminal for --format png|pdf|svg into VAR (1200 x 800
# at 13 pt; the pdf 10 x 6.67 in at 11 pt); another FORMAT is a usage error.
bk_terminal() {
    local _bk_terminal
    case $2 in
        png) _bk_terminal="pngcairo size 1200,800 font 'Sans,13'" ;;
        pdf) _bk_terminal="pdfcairo size 10in,6.67in font 'Sans,11' linewidth 0.6" ;;
        svg) _bk_terminal="svg size 1200,800 font 'Sans,13' background rgb 'white'" ;;
        *) bk_usage "--format must be png, pdf or svg, got '$2'" ;;
    esac
    printf -v "$1" '%s' "$_bk_terminal"
}

# bk_gp_quote TEXT: TEXT for the inside of a single-quoted gnuplot string (a quote doubled).
bk_gp_quote() {
    local text=$1 quote="'"
    printf '%s' "${text//$quote/$quote$quote}"
}
