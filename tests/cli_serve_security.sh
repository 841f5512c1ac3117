#!/usr/bin/env bash
# What serve says about its own security: a TLS key that belongs to another certificate is refused
# by name (not as a port it could not bind), and a server without authentication says loudly, in
# its banner and on stderr, that anyone may subscribe. Each server stops itself within 2 s.
set -euo pipefail
probecast=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }

"$probecast" bake --scene builtin:cornell --grid 2,2,2 --spp 4 --updates 1 --out "$work/v.pcpv" >/dev/null
for name in a b; do
  openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 1 -subj "/CN=localhost" \
    -keyout "$work/$name.key" -out "$work/$name.crt" 2>/dev/null
done
port=$((20000 + RANDOM % 20000))
serve=(serve --probes "$work/v.pcpv" --listen "127.0.0.1:$port" --seconds 1)

# Certificate a with key b.
rc=0
"$probecast" "${serve[@]}" --tls-cert "$work/a.crt" --tls-key "$work/b.key" --token t >"$work/mismatch.log" 2>&1 || rc=$?
[ "$rc" -eq 1 ] || fail "a mismatched key: exit code $rc, expected 1: $(cat "$work/mismatch.log")"
grep -q "the TLS key does not match the certificate" "$work/mismatch.log" ||
  fail "a mismatched key is not named: $(cat "$work/mismatch.log")"
grep -q "cannot listen" "$work/mismatch.log" && fail "a mismatched key is reported as a port: $(cat "$work/mismatch.log")"

# A key file that holds no key at all.
rc=0
"$probecast" "${serve[@]}" --tls-cert "$work/a.crt" --tls-key "$work/a.crt" --token t >"$work/nokey.log" 2>&1 || rc=$?
[ "$rc" -eq 1 ] || fail "a certificate given as the key: exit code $rc, expected 1"
grep -q "the TLS key is not an unencrypted PEM private key" "$work/nokey.log" ||
  fail "a certificate given as the key is not named: $(cat "$work/nokey.log")"

# The matching pair serves.
rc=0
"$probecast" "${serve[@]}" --tls-cert "$work/a.crt" --tls-key "$work/a.key" --token t >"$work/tls.log" 2>&1 || rc=$?
[ "$rc" -eq 0 ] || fail "a matching pair: exit code $rc: $(cat "$work/tls.log")"
grep -q "on port $port (TLS, token)" "$work/tls.log" || fail "the TLS banner: $(cat "$work/tls.log")"

# --no-auth: the banner and a warning on stderr.
rc=0
"$probecast" "${serve[@]}" --plaintext --no-auth >"$work/open.out" 2>"$work/open.err" || rc=$?
[ "$rc" -eq 0 ] || fail "--no-auth: exit code $rc: $(cat "$work/open.err")"
grep -q "(plaintext, NO AUTHENTICATION: anyone may subscribe)" "$work/open.out" ||
  fail "the --no-auth banner does not say anyone may subscribe: $(cat "$work/open.out")"
grep -q "WARNING: no authentication (--no-auth): anyone who can reach port $port may subscribe" "$work/open.err" ||
  fail "--no-auth gives no warning on stderr: $(cat "$work/open.err")"
echo "serve security messages ok"
