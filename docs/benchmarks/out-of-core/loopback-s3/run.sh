#!/usr/bin/env bash
# Folder against loopback S3 (moto): bench --stream and render, on this machine.
set -u
export XDG_RUNTIME_DIR=/tmp/xdg
L=/work/main/target/release/leapview
out=/tmp/st/s3bench; rm -rf $out; mkdir -p $out
exec 3> >(/work/main/.venv/bin/python /work/main/scripts/python/s3_server.py bkt /tmp/st/s512.ome.zarr > $out/server.json 2>/dev/null)
for _ in $(seq 120); do [[ -s $out/server.json ]] && break; sleep 0.5; done
P=$(python3 -c "import json;print(json.load(open('$out/server.json'))['port'])")
export AWS_ENDPOINT_URL=http://127.0.0.1:$P AWS_ALLOW_HTTP=true AWS_ACCESS_KEY_ID=testing AWS_SECRET_ACCESS_KEY=testing AWS_REGION=us-east-1
for round in 1 2; do
for src in /tmp/st/s512.ome.zarr s3://bkt/s512.ome.zarr http://127.0.0.1:$P/bkt/s512.ome.zarr; do
  name=$(echo $src | cut -d: -f1 | tr -d /); [[ $name == tmpsts512.ome.zarr ]] && name=folder
  /usr/bin/time -f "%e s %M KB" $L render $src --ram-budget 64MiB --gpu-budget 512MiB --size 320x180 -o $out/$name.png > $out/render-$name-$round.log 2>&1
  $L bench --stream $src --out $out/stream-$name-$round --ram-budget 64MiB --gpu-budget 512MiB --stream-size 320x180 --stream-frames 6 > $out/stream-$name-$round.log 2>&1
done
done
exec 3>&-
