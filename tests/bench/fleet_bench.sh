#!/usr/bin/env bash
# The fleet view at scale (issue 35; docs/benchmarks.md "The fleet view at 1,000 machines"): a
# synthetic central store of MACHINES machines x MONTHS monthly runs (results only: no reading
# chunks, which the fleet view never reads), made on a throwaway PostgreSQL server by
# generate_series on the server (through the schema's own triggers, as a sync fills them); then
# the first view's requests timed with curl (the fleet's summary and the first site's first page of
# machines), a machine opened (its trends and history, with and without a chosen date), beside the
# peer measured in the same run: one scan of the fleet's values table (the trend aggregation reads
# each value once); and the page's render in headless Chromium (navigation to the first view
# rendered, at 1366x768). The machine's load (uptime) is printed before and after.
# With READING_MONTHS > 0, each machine's last READING_MONTHS runs get readings: the chunks of the
# demo's own runs of the same kind (a linear run of X's stops; a ballbar circle), as daq stored
# and sent them (their checksums hold), copied on the server under each run; then `daq bench
# sync` is run against the same server (sync throughput beside COPY's, in the same run).
# Usage: fleet_bench.sh DAQ_BINARY [MACHINES=1000] [MONTHS=120] [SCREENSHOT_DIR] [READING_MONTHS=0]
set -eu
DAQ=$(realpath "$1")
MACHINES=${2:-1000}
MONTHS=${3:-120}
SHOTS=${4:-}
[ -z "$SHOTS" ] || mkdir -p "$SHOTS"
READING_MONTHS=${5:-0}
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../cli/check.sh"
source "$HERE/../cli/pg_server.sh"
TMP=$(mktemp -d)
PGTMP=$(mktemp -d /tmp/caldaq-pg.XXXXXX)
SERVE_PID=
trap '[ -n "$SERVE_PID" ] && kill $SERVE_PID 2>/dev/null; pg_stop; rm -rf "$TMP" "$PGTMP"' EXIT
sql() { "$PG_BIN/psql" -X -q -At -v ON_ERROR_STOP=1 "$PG_URL" "$@"; }
secs() { date +%s.%N; }
# FLEET_STORE=URI: a store this script made before, on a server still running (another daq
# binary measured on the same store): its history is not made again (READING_MONTHS > 0 still
# adds readings, once).
made="not made here (FLEET_STORE)"
if [ -n "${FLEET_STORE:-}" ]; then
  PG_URL=$FLEET_STORE
else
pg_start "$PGTMP" >/dev/null
# The schema, made by a sync as on a real server: the demo's store sent.
(cd "$TMP" && "$DAQ" demo --quiet --db demo.sqlite --capture demo.cdq >demo.log 2>&1)
"$DAQ" sync --db "$TMP/demo.sqlite" --to "$PG_URL" --quiet >/dev/null

t=$(secs)
sql -v machines="$MACHINES" -v months="$MONTHS" <<'EOF'
-- 20 sites; a month between runs; each machine's axes X, Y, Z and a circle in XY in turn; E drifts
-- by 0 to 1.8 um a year by machine (some leave their 10 um limit within the 10 years), G by 0 to
-- 2 um a year, squareness about a machine's own offset; noise 0.5 um.
INSERT INTO caldaq.machines(name, uuid, site)
  SELECT format('Machine %s', lpad(i::text, 4, '0')), gen_random_uuid(), ''
  FROM generate_series(1, :machines) AS i;
UPDATE caldaq.machines SET site = format('Site %s', lpad((id % 20)::text, 2, '0')) WHERE name LIKE 'Machine %';
INSERT INTO caldaq.runs(uuid, machine_id, source_run_id, campaign, kind, axis, settings_json,
    capture_path, software_version, started_unix_ms, ended_unix_ms, status, note, synced_unix_ms,
    site)
  SELECT gen_random_uuid(), m.id, mo + 1, 'bench', CASE WHEN mo % 4 = 3 THEN 'circle' ELSE 'linear' END,
    (ARRAY['X', 'Y', 'Z', 'XY'])[mo % 4 + 1],
    json_build_object('context', json_build_object(
      'customer', json_build_object('name', 'Bench', 'site', format('Site %s', lpad((m.id % 20)::text, 2, '0'))),
      'machine', json_build_object('name', m.name, 'make', 'Bench', 'model', 'B-1', 'serial_number', m.id::text),
      'operator', 'bench',
      'tolerances', CASE WHEN mo % 4 = 3 THEN '{"G_um": 15, "diagnostics": {"squareness": 20}}'::json
                         ELSE '{"E_um": 10, "M_um": 8, "R_um": 4, "B_um": 3}'::json END,
      'instruments', json_build_array(
        json_build_object('id', 'laser', 'role', 'laser', 'driver', 'ids3010', 'serial_number',
          format('L-%s', m.id % 200), 'certificate', 'C-L', 'calibration_due',
          to_char(date '2026-06-01' + (m.id * 37 % 500)::int, 'YYYY-MM-DD')),
        json_build_object('id', 'air', 'role', 'weather station', 'driver', 'ptu300',
          'serial_number', format('P-%s', m.id), 'certificate', 'C-P', 'calibration_due',
          to_char(date '2026-09-01' + (m.id * 11 % 400)::int, 'YYYY-MM-DD')))))::text,
    '', 'bench', s.ms, s.ms + 3600000, 'complete', '', 0, m.site
  FROM caldaq.machines AS m, generate_series(0, :months - 1) AS mo,
    LATERAL (SELECT (extract(epoch FROM now() - make_interval(months => :months)) * 1000)::bigint
                    + mo::bigint * 2629800000 + (m.id % 28) * 86400000 AS ms) AS s
  WHERE m.name LIKE 'Machine %';
-- Each result's verdict as daq's sync stores it (central schema 12: the server judges nothing),
-- against the bench's own tolerances above, the value as printed to 0.001: a synthetic store's
-- judgement, not a second copy of daq's rule (the fleet reads only the stored verdict).
INSERT INTO caldaq.results(run_uuid, source_result_id, standard, json, created_unix_ms,
    provenance_json, fingerprint, verdict, verdict_failed)
  SELECT r.uuid, 1, CASE r.kind WHEN 'circle' THEN 'ISO 230-4:2005' ELSE 'ISO 230-2:2014' END, d.doc,
    r.started_unix_ms + 3600000, '{"how": "acquired", "software": "bench"}', md5(d.doc),
    CASE WHEN f.failed = '' THEN 'pass' ELSE 'fail' END, f.failed
  FROM caldaq.runs AS r JOIN caldaq.machines AS m ON m.id = r.machine_id,
    LATERAL (SELECT (r.source_run_id - 1) / 12.0 AS years) AS y,
    LATERAL (SELECT 3 + (m.id % 7) * 0.3 * y.years + random() * 0.5 AS e,
                    5 + (m.id % 5) * 0.4 * y.years + random() * 0.5 AS g,
                    (m.id % 9 - 4) * 2 + random() - 0.5 AS sq) AS v,
    LATERAL (SELECT CASE WHEN r.kind = 'circle' THEN json_build_object(
        'schema', 'caldaq.circle.v2', 'standard', 'ISO 230-4:2005', 'standard_key', 'iso230-4:2005',
        'radius_mm', 100, 'feed_mm_per_min', 1000, 'plane', 'XY',
        'iso230_4', json_build_object('G_bi_um', v.g, 'G_ccw_um', v.g * 0.9, 'G_cw_um', v.g,
                                      'F_max_um', v.g / 2, 'F_min_um', -v.g / 2, 'arc_deg', 360),
        'diagnostics', json_build_array(
          json_build_object('key', 'squareness', 'name', 'Squareness', 'value', v.sq, 'unit', 'um/m'),
          json_build_object('key', 'servo_mismatch', 'name', 'Servo mismatch', 'value', 0.2, 'unit', 'ms'),
          json_build_object('key', 'scale_mismatch', 'name', 'Scale mismatch', 'value', 3, 'unit', 'um/m')),
        'notes', json_build_array())
      ELSE json_build_object(
        'schema', 'caldaq.iso230-2.v1', 'standard', json_build_object('key', 'iso230-2:2014', 'title', 'ISO 230-2:2014'),
        'bidirectional', true, 'runs_per_direction', 5,
        'targets', (SELECT json_agg(json_build_object('target_mm', k * 50, 'runs_up', 5,
            'mean_up_um', v.e * k / 10, 's_up_um', 0.3, 'mean_bi_um', v.e * k / 10, 'runs_down', 5,
            'mean_down_um', v.e * k / 10 - 0.4, 's_down_um', 0.3, 'reversal_um', 0.4))
          FROM generate_series(0, 10) AS k),
        'axis', json_build_object(
          'E_bi', json_build_object('symbol', 'E', 'value_um', v.e),
          'M', json_build_object('symbol', 'M', 'value_um', v.e * 0.6),
          'R_bi', json_build_object('symbol', 'R', 'value_um', 1.4),
          'B', json_build_object('symbol', 'B', 'value_um', 0.4),
          'A_bi', json_build_object('symbol', 'A', 'value_um', v.e + 1.4)),
        'warnings', json_build_array(), 'notes', json_build_array()) END::text AS doc) AS d,
    LATERAL (SELECT CASE WHEN r.kind = 'circle'
                      THEN CASE WHEN round(v.g::numeric, 3) > 15 THEN 'G' ELSE '' END
                      ELSE concat_ws(', ', CASE WHEN round(v.e::numeric, 3) > 10 THEN 'E' END,
                                     CASE WHEN round((v.e * 0.6)::numeric, 3) > 8 THEN 'M' END)
                    END AS failed) AS f
  WHERE r.campaign = 'bench';
-- Each run sent once (version 1) and its result placed in that version (central schemas 11, 12:
-- the fleet counts only the results of a run's current version).
INSERT INTO caldaq.run_versions(run_uuid, version, fingerprint, status, sent_by, sent_from,
    sent_store, sent_unix_ms)
  SELECT r.uuid, 1, md5(r.uuid::text), r.status, 'bench', 'bench', 'bench', r.started_unix_ms + 3600000
  FROM caldaq.runs AS r WHERE r.campaign = 'bench';
INSERT INTO caldaq.result_versions(run_uuid, version, source_result_id, superseded_by)
  SELECT s.run_uuid, 1, s.source_result_id, NULL
  FROM caldaq.results AS s JOIN caldaq.runs AS r ON r.uuid = s.run_uuid WHERE r.campaign = 'bench';
-- Every tenth machine's X compensated 5 years ago (a positioning table): X's lines start there.
INSERT INTO caldaq.compensations(machine_id, source, axis, format, created_unix_ms, json, fingerprint, site)
  SELECT m.id, 'bench', 'X', 'csv', (extract(epoch FROM now() - interval '5 years') * 1000)::bigint,
    '{"schema": "caldaq.compensation.v1", "format": "csv"}', md5('bench ' || m.id), m.site
  FROM caldaq.machines AS m WHERE m.name LIKE 'Machine %' AND m.id % 10 = 0;
-- A reviewer approved every result older than 90 days.
INSERT INTO caldaq.approvals
  SELECT s.run_uuid, s.fingerprint, 1, 'reviewer', s.created_unix_ms + 86400000
  FROM caldaq.results AS s JOIN caldaq.runs AS r ON r.uuid = s.run_uuid
  WHERE r.campaign = 'bench' AND r.started_unix_ms < (extract(epoch FROM now() - interval '90 days') * 1000)::bigint;
-- Loaded in one go, every run rewrote its instruments' rows (240,000 row versions of 1,200 rows):
-- syncs spread over time leave autovacuum room to reuse that space; here it is compacted once.
VACUUM FULL caldaq.fleet_instruments;
ANALYZE;
EOF
made=$(echo "$(secs) - $t" | bc)
fi
if [ "$READING_MONTHS" -gt 0 ]; then
  t=$(secs)
  sql -v months="$MONTHS" -v reading_months="$READING_MONTHS" <<'EOF'
-- The demo's two runs (a linear run of X: 11 targets, 5 runs each way, 3 s dwells; a ballbar
-- circle at 1 kHz), their chunks as the demo's sync sent them, under each bench run of the same
-- kind in the last :reading_months months of every machine.
INSERT INTO caldaq.reading_chunks
  SELECT r.uuid, c.seq, c.device, c.channel, c.quantity, c.first_ns, c.last_ns, c.count, c.encoding,
    c.crc, c.stored_checksum, c.data
  FROM caldaq.runs AS r
    JOIN (SELECT DISTINCT ON (kind) kind, uuid FROM caldaq.runs WHERE campaign <> 'bench'
          ORDER BY kind, started_unix_ms) AS d ON d.kind = r.kind
    JOIN caldaq.reading_chunks AS c ON c.run_uuid = d.uuid
  WHERE r.campaign = 'bench' AND r.source_run_id > :months - :reading_months;
ANALYZE caldaq.reading_chunks;
EOF
  read_made=$(echo "$(secs) - $t" | bc)
  read -r chunk_runs readings chunk_mb table_mb <<<"$(sql -F ' ' -c "SELECT count(DISTINCT run_uuid), sum(count), sum(length(data)) / 1000000, pg_total_relation_size('caldaq.reading_chunks') / 1000000 FROM caldaq.reading_chunks")"
  echo "readings: $readings in $chunk_runs runs ($chunk_mb MB of chunk data, the table and its index $table_mb MB); made in ${read_made} s"
  # Sync throughput into this store, beside COPY's ceiling into it, in the same run.
  echo "load before the sync bench: $(uptime)"
  "$DAQ" bench sync --to "$PG_URL" --minutes 2 --runs 5 --rounds 3 --dir "$TMP"
fi
read -r runs results values approvals doc_bytes db_mb <<<"$(sql -F ' ' -c "SELECT (SELECT count(*) FROM caldaq.runs), (SELECT count(*) FROM caldaq.results), (SELECT count(*) FROM caldaq.fleet_values), (SELECT count(*) FROM caldaq.approvals), (SELECT avg(length(json))::int FROM caldaq.results), pg_database_size(current_database()) / 1000000")"
echo "store: $MACHINES machines x $MONTHS months: $runs runs, $results results (about $doc_bytes bytes of JSON each), $values fleet values, $approvals approvals; made in ${made} s; database $db_mb MB"

# The peer: one scan of every value the trends aggregate.
for i in 1 2 3; do
  t=$(secs); sql -c "SELECT count(*), sum(value) FROM caldaq.fleet_values WHERE current AND trend" >/dev/null
  echo "peer: one scan of the trend values (psql, connect included): $(echo "($(secs) - $t) * 1000" | bc | cut -d. -f1) ms"
done

"$DAQ" serve --db "$PG_URL" --port 0 >"$TMP/serve.log" 2>&1 &
SERVE_PID=$!
for _ in $(seq 300); do grep -q "http://" "$TMP/serve.log" && break; sleep 0.1; done
URL=$(sed -n 's|.*\(http://127.0.0.1:[0-9]*\)/.*|\1|p' "$TMP/serve.log")
[ -n "$URL" ] || { cat "$TMP/serve.log"; exit 1; }
echo "load before the requests: $(uptime)"
# The first view: the summary, then the first site's first page (what the page asks for).
curl -sf -o "$TMP/fleet.json" "$URL/api/fleet"
SITE=$("$PY" -c 'import json, sys, urllib.parse; print(urllib.parse.quote(json.load(open(sys.argv[1]))["sites"][0]["site"], safe=""))' "$TMP/fleet.json")
for i in 1 2 3 4 5; do
  a=$(curl -sf -o "$TMP/fleet.json" -w "%{time_total} %{size_download}" "$URL/api/fleet")
  b=$(curl -sf -o "$TMP/site.json" -w "%{time_total} %{size_download}" "$URL/api/fleet/sites/$SITE/page/1")
  echo "first view, one after the other: GET /api/fleet ${a% *} s (${a#* } bytes) + GET /api/fleet/sites/$SITE/page/1 ${b% *} s (${b#* } bytes) = $(echo "${a% *} + ${b% *}" | bc) s"
done
# As the page asks: the summary and the first site's first page at once (two of the serve's
# pooled connections).
# Each curl's own time_total (the wall time around them is mostly starting two curl processes:
# 0.4 - 0.7 s at load 9 - 12 for answers of 0.02 - 0.06 s).
for i in 1 2 3 4 5; do
  curl -sf -o "$TMP/fleet.json" -w "%{time_total}" "$URL/api/fleet" >"$TMP/a.time" &
  b=$(curl -sf -o "$TMP/first.json" -w "%{time_total}" "$URL/api/fleet/first-site")
  wait $!
  echo "first view, both at once: GET /api/fleet $(cat "$TMP/a.time") s and /api/fleet/first-site $b s"
done
OPEN=$(((MACHINES + 1) / 2))  # a machine in the middle of the fleet (500 of 1,000)
for i in 1 2 3; do
  curl -sf -o "$TMP/machine.json" -w "a machine opened: GET /api/fleet/machines/$OPEN: %{time_total} s, %{size_download} bytes\n" "$URL/api/fleet/machines/$OPEN" || echo "no machine $OPEN"
  curl -sf -o /dev/null -w "a date chosen: GET /api/fleet/machines/$OPEN/since/2024-01-01: %{time_total} s, %{size_download} bytes\n" "$URL/api/fleet/machines/$OPEN/since/2024-01-01" || echo "no machine $OPEN"
done
curl -sf -o "$TMP/site-last.json" -w "another page: GET /api/fleet/sites/$SITE/page/2: %{time_total} s, %{size_download} bytes\n" "$URL/api/fleet/sites/$SITE/page/2" || echo "no page 2"
"$PY" - "$TMP/fleet.json" "$TMP/site.json" "$TMP/machine.json" "$OPEN" <<'EOF'
import collections, json, sys
d, site, machine = (json.load(open(p)) for p in sys.argv[1:4])
inst = d["instruments"]["statuses"]
counts = collections.Counter()
for m in site["machines"]:
    counts.update(m["trends"])
windows = collections.Counter(t["window"]["reason"] for t in machine["trends"])
print(f"answer: {len(d['sites'])} sites, {d['machines']} machines; the first site {site['count']} machines, "
      f"{site['pages']} pages, its first page's trend counts {dict(counts)}; instruments {inst} "
      f"({d['instruments']['listed']} listed); awaiting approval {d['awaiting_approval']['count']}; "
      f"machine {sys.argv[4]}'s windows {dict(windows)}")
EOF
kill $SERVE_PID
wait $SERVE_PID 2>/dev/null || true
SERVE_PID=
# The page in Chromium: twice a new `daq serve` and its first load, then two more: the first
# time with the browser's own first page too, the second with the browser warm.
HERE=$HERE "$PY" - "$DAQ" "$PG_URL" "${SHOTS:-$TMP}" <<'EOF'
import os, re, subprocess, sys, time
sys.path.insert(0, os.path.join(os.environ["HERE"], "..", "web"))
from webdriver import Browser
daq, pg_url, shots = sys.argv[1:4]
with Browser(width=1366, height=768) as b:
    for serve in ("the browser's first page", "the browser warm"):
        t0 = time.monotonic()
        p = subprocess.Popen([daq, "serve", "--db", pg_url, "--port", "0"], stdout=subprocess.PIPE,
                             text=True)
        line = p.stdout.readline()
        url = re.search(r"http://127\.0\.0\.1:\d+", line).group(0)
        print(f"daq serve started ({serve}): ready in {time.monotonic() - t0:.2f} s")
        try:
            for i in range(3):
                b.get(url + "/")
                b.wait("return document.body.dataset.complete !== undefined", timeout_s=60,
                       what="the fleet")
                ms, done, n, api = b.js(
                    "return [Number(document.body.dataset.rendered), "
                    "Number(document.body.dataset.complete), "
                    "document.querySelectorAll('details.machine').length, "
                    "Math.max(...performance.getEntriesByType('resource')"
                    ".filter(r => r.name.includes('/api/')).map(r => r.responseEnd))];")
                which = "first load after the serve started" if i == 0 else "then"
                print(f"page ({which}): navigation to the first view rendered and painted {ms:.0f} "
                      f"ms ({n} machines listed; its answers in at {api:.0f} ms); the lists below "
                      f"it too {done:.0f} ms")
            b.screenshot(os.path.join(shots, "fleet-bench.png"))
        finally:
            p.terminate()
            p.wait()
EOF
echo "load after: $(uptime)"
