#!/usr/bin/env bash
# Regenerates fuzz/corpus from a tiny simulated dataset and its map, plus the
# bad-input reproducers of issue 22. Usage: fuzz/make_corpus.sh MONOMAP_BINARY
set -euo pipefail
M=$1
C=$(cd "$(dirname "$0")" && pwd)/corpus
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$M" simulate hallway -o "$T/ds" --frames 6 --width 64 --height 48 >/dev/null
"$M" simulate hallway -o "$T/ds30" --frames 30 --width 64 --height 48 >/dev/null
"$M" build "$T/ds30" -o "$T/map" --no-ba >/dev/null
rm -rf "$C"
mkdir -p "$C"/{camera_yaml,camera_mount,dataset,feature_table,image,map,ply}
D=$T/ds
sep() { printf -- '----\n'; }
# camera.yaml
cp "$D/camera.yaml" "$C/camera_yaml/valid.yaml"
printf 'image_width: 160\nimage_height: 120\ncamera_matrix: 5\n' > "$C/camera_yaml/wrong_node_kind.yaml"
sed 's/^image_width:.*/image_width: 100000/;s/^image_height:.*/image_height: 100000/' "$D/camera.yaml" > "$C/camera_yaml/huge.yaml"
printf '[1, 2, 3]\n' > "$C/camera_yaml/list_root.yaml"
# camera_mount.yaml
cp "$D/camera_mount.yaml" "$C/camera_mount/valid.yaml"
printf 'base_from_cam: 5\n' > "$C/camera_mount/wrong_node_kind.yaml"
printf 'base_from_cam:\n  translation: [1e400, 0]\n  rotation_xyzw: {a: 1}\n' > "$C/camera_mount/bad_values.yaml"
# dataset: rgb.txt, odometry.txt, odometry2d.txt, groundtruth.txt,
# camera.yaml, camera_mount.yaml separated by "----" lines (3 images exist).
rgb() { head -4 "$D/rgb.txt"; }
{ rgb; sep; head -4 "$D/odometry.txt"; sep; sep; head -4 "$D/groundtruth.txt"; sep; cat "$D/camera.yaml"; } > "$C/dataset/valid_odometry"
{ rgb; sep; sep; head -4 "$D/odometry2d.txt"; sep; sep; cat "$D/camera.yaml"; sep; cat "$D/camera_mount.yaml"; } > "$C/dataset/valid_odometry2d"
{ rgb; sep; head -4 "$D/odometry.txt"; echo "99999 1e300 0 0 0 0 0 1"; sep; sep; sep; cat "$D/camera.yaml"; } > "$C/dataset/odometry_huge_translation"
{ rgb; sep; sep; head -4 "$D/odometry2d.txt"; echo "99999 0 0 1e300"; sep; sep; cat "$D/camera.yaml"; sep; cat "$D/camera_mount.yaml"; } > "$C/dataset/odometry2d_huge_yaw"
{ rgb; echo "1000.1 rgb/missing.png"; sep; head -4 "$D/odometry.txt"; echo "99999 1 2 3"; sep; sep; sep; cat "$C/camera_yaml/wrong_node_kind.yaml"; } > "$C/dataset/malformed"
# feature table
head -c 1500 "$T/map/features.csv" | sed '$d' > "$C/feature_table/valid.csv"
printf '# bad\n1,2,3,nan,1e400,-1\n' > "$C/feature_table/bad_numbers.csv"
# images: tiny PNG and JPEG, a truncated one and a huge header claim
python3 - "$D/rgb/000000.png" "$C/image" <<'PY'
import struct, sys, zlib
png = open(sys.argv[1], 'rb').read()
out = sys.argv[2]
open(out + '/valid.png', 'wb').write(png)
open(out + '/truncated.png', 'wb').write(png[:len(png) // 2])
# IHDR claiming 100000x100000 (CRC fixed so the decoder reaches the size).
ihdr = bytearray(png[12:29])
ihdr[4:12] = struct.pack('>II', 100000, 100000)
crc = struct.pack('>I', zlib.crc32(bytes(ihdr)) & 0xffffffff)
open(out + '/huge_header.png', 'wb').write(png[:12] + bytes(ihdr) + crc + png[33:])
PY
python3 -c "import cv2" 2>/dev/null && python3 -c "
import cv2, numpy as np, sys
img = (np.arange(64*48*3) % 251).astype(np.uint8).reshape(48, 64, 3)
ok, jpg = cv2.imencode('.jpg', img); open('$C/image/valid.jpg', 'wb').write(jpg.tobytes())
j = jpg.tobytes(); open('$C/image/truncated_eoi.jpg', 'wb').write(j[:len(j)//2] + b'\xff\xd9')
" || true
# map: map.json, trajectory.txt, points.ply separated by "----" lines
{ cat "$T/map/map.json"; sep; head -5 "$T/map/trajectory.txt"; sep; cat "$T/map/points.ply"; } > "$C/map/valid"
sed 's/"fx": [0-9.]*/"fx": 1e400/' "$T/map/map.json" > "$C/map/number_overflow"
sed 's/"width": [0-9]*/"width": 100000/;s/"height": [0-9]*/"height": 100000/' "$T/map/map.json" > "$C/map/camera_huge"
# points.ply
cp "$T/map/points.ply" "$C/ply/valid.ply"
H='ply\nformat ascii 1.0\n'
printf "${H}element junk 4000000000\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 2\n0.1 0 2\n0.2 0 2\n" > "$C/ply/huge_count_no_properties.ply"
printf "${H}element face 1\nproperty list uchar int i\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n1e300 1\n0 0 2\n0.1 0 2\n0.2 0 2\n" > "$C/ply/list_length_overflow.ply"
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n' > "$C/ply/binary.ply"
head -c 24 /dev/zero >> "$C/ply/binary.ply"
du -sh "$C"
