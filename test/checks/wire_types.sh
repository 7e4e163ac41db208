#!/usr/bin/env bash
# Generated structs stay at the edge (docs/architecture.md): fails, printing `file:line: what` for each
# finding, when a C++ source outside the wire layers
#   - touches a wire sequence's fields (._buffer, ._length, ._maximum, ._release; also through -> or ::)
#     or names a dds_sequence_* type: read with dds::elements(), fill with dds::wire_sequence(),
#     dds::wire_buffer() or dds::alloc_sequence() (rigger/dds/sequences.hpp, conversions.hpp);
#   - passes a topic descriptor's .name to a Reader or Writer together with a QoS: pass the descriptor,
#     whose own profile applies (rigger/dds/pubsub.hpp), or the descriptor and a QoS computed for a reason.
#
# The wire layers, where this is the job: common/dds (the DDS layer), common/protocol and
# common/*_protocol (the protocol libraries), common/ros2 (ROS 2 messages on the wire). Generated code is
# not tracked (idlc writes into the build tree) and is not read.
#
# Usage: wire_types.sh REPOSITORY_ROOT
set -euo pipefail

# path<TAB>the reason it may touch wire fields (none today).
readonly allowed=(
)

root=${1:?usage: wire_types.sh REPOSITORY_ROOT}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=source_files.sh
source "$here/source_files.sh"
cd "$root"

is_checked() {
  case "$1" in
    */node_modules/* | node_modules/* | build*/* | */generated/*) return 1 ;;
    common/dds/* | common/protocol/* | common/*_protocol/* | common/ros2/*) return 1 ;;
    *.cpp | *.hpp | *.h | *.cc) return 0 ;;
    *) return 1 ;;
  esac
}

# Prints `file:line: what` for each finding in the files named on stdin (NUL-separated). A statement may
# span lines, so the descriptor rule reads each file whole.
scan() {
  perl -0 -ne '
    BEGIN { $/ = "\0"; }
    chomp(my $path = $_);
    open(my $fh, "<", $path) or next;
    local $/;
    my $text = <$fh>;
    close $fh;
    my $line_of = sub { my ($pos) = @_; return 1 + (substr($text, 0, $pos) =~ tr/\n//); };
    while ($text =~ /(?:\.|->|::)(_(?:buffer|length|maximum|release))\b/g) {
      printf "%s:%d: raw wire sequence field %s\n", $path, $line_of->($-[0]), $1;
    }
    while ($text =~ /\b(dds_sequence_\w+)/g) {
      printf "%s:%d: raw wire sequence type %s\n", $path, $line_of->($-[0]), $1;
    }
    while ($text =~ /\b(\w+)\.name\s*,\s*((?:\w+::)*q(?:os)?::\w+(?=\s*\()|\w*_qos\b|\bqos\b)/g) {
      printf "%s:%d: %s.name passed with the QoS %s: pass the descriptor %s\n", $path, $line_of->($-[0]), $1, $2, $1;
    }
  '
}

files=()
while IFS= read -r -d '' path; do
  is_checked "$path" || continue
  [[ -f "$path" ]] || continue  # deleted in the work tree, not yet in the index
  is_allowed "$path" && continue
  files+=("$path")
done < <(list_files)
findings=$(printf '%s\0' "${files[@]}" | scan | sort -t: -k1,1 -k2,2n)

if [[ -n "$findings" ]]; then
  echo "$findings"
  echo "wire_types: convert at the edge with the helpers of rigger/dds/sequences.hpp and conversions.hpp," \
    "or in the protocol library; open topics by their descriptor" >&2
  exit 1
fi
echo "wire_types: ${#files[@]} C++ files outside the wire layers, no raw wire fields, no descriptor .name with a QoS"
