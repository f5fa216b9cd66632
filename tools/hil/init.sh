#!/bin/sh
# /init of the HIL initramfs (tools/hil/hil-bench.sh): vcan0, feeder → lbrsim run (and
# candump -l), replay of lbrsim's recorded log and of candump's, canplayer playing the
# recorded log into a second lbrsim run; results on the console between HIL markers, power off.
export PATH=/bin:/sbin
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev 2>/dev/null
mount -t tmpfs tmp /tmp
for m in can can-raw can-dev vcan; do insmod /mods/$m.ko || echo "HIL-ERROR insmod $m"; done
ip link add dev vcan0 type vcan || echo "HIL-ERROR ip link add"
ip link set up vcan0 || echo "HIL-ERROR ip link set up"
FAULTS="$(cat /data/faults)"
lbrsim --log-level warn run --profile /data/profile.toml --source can:vcan0 --out /tmp/live \
  --record /tmp/can.log --quiet > /tmp/live.txt 2>&1 &
LBR=$!
# Start feeding once lbrsim has bound its filtered socket (its SYNC filter shows up here).
i=0
while ! grep -q vcan0 /proc/net/can/rcvlist_fil 2>/dev/null && [ $i -lt 600 ]; do sleep 0.1; i=$((i+1)); done
sleep 0.5
# can-utils' candump -l records what the feeder sends (-D: it stays through the interface
# going down below); its file is replayed at the end.
mkdir -p /tmp/cd
(cd /tmp/cd && exec candump -D -l vcan0) &
CANDUMP=$!
sleep 0.3
# The feeder plays the drives: highest priority, so its SYNC + TPDO bursts are not split.
lbr-feed-can --priority 90 --profile /data/profile.toml --program /data/program.moves --iface vcan0 $FAULTS > /tmp/feed.json &
FEED=$!
# Interface down for a while in the middle: lbrsim must count it, reconnect and go on.
sleep 1.5
ip link set down vcan0
sleep 0.4
ip link set up vcan0
wait $FEED
sleep 1
kill -INT $LBR
wait $LBR
echo "HIL-LIVE-RC $?"
kill -INT $CANDUMP
wait $CANDUMP
CDLOG="$(ls /tmp/cd/candump-*.log | head -1)"
lbrsim --log-level warn run --profile /data/profile.toml --source replay:/tmp/can.log --speed 0 --out /tmp/replay \
  --quiet > /tmp/replay.txt 2>&1
echo "HIL-REPLAY-RC $?"
# candump's own file (what the feeder sent) through replay:.
lbrsim --log-level warn run --profile /data/profile.toml --source replay:$CDLOG --speed 0 --out /tmp/replay-cd \
  --quiet > /tmp/replay-cd.txt 2>&1
echo "HIL-CANDUMP-REPLAY-RC $?"
# canplayer plays lbrsim's recording onto vcan0 (its timing) for a second live run. It sends
# what is due every 1 ms (its -g), which TCG stretches: TPDOs may come 50 ms after their SYNC.
sed 's/^late_ms = .*/late_ms = 50.0/' /data/profile.toml > /tmp/play.toml
lbrsim --log-level warn run --profile /tmp/play.toml --source can:vcan0 --out /tmp/play --quiet > /tmp/play.txt 2>&1 &
LBR=$!
i=0
while ! grep -q vcan0 /proc/net/can/rcvlist_fil 2>/dev/null && [ $i -lt 600 ]; do sleep 0.1; i=$((i+1)); done
sleep 0.5
canplayer -I /tmp/can.log
echo "HIL-CANPLAYER-RC $?"
sleep 1
kill -INT $LBR
wait $LBR
echo "HIL-PLAY-RC $?"
echo "HIL-FEED $(cat /tmp/feed.json)"
echo "HIL-LIVE $(tr -d '\n' < /tmp/live/metrics.json)"
echo "HIL-REPLAY $(tr -d '\n' < /tmp/replay/metrics.json)"
echo "HIL-CANDUMP-REPLAY $(tr -d '\n' < /tmp/replay-cd/metrics.json)"
echo "HIL-PLAY $(tr -d '\n' < /tmp/play/metrics.json)"
# Both logs to the host, which compares them line by line (format = candump's).
echo "HIL-LOG-LBRSIM $(gzip -c /tmp/can.log | base64 | tr -d '\n')"
echo "HIL-LOG-CANDUMP $(gzip -c $CDLOG | base64 | tr -d '\n')"
cat /tmp/live.txt /tmp/replay.txt /tmp/replay-cd.txt /tmp/play.txt
echo "HIL-DONE"
poweroff -f
