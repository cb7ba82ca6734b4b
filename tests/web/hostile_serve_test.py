#!/usr/bin/env python3
"""Hostile clients against a real `daq serve` on loopback (issue 15).

Every case sends what a hostile web page, a DNS-rebinding attacker, a confused script or a
descriptor-exhausting client would send, asserts the status code (or that the connection is
closed), and then asserts that the server still answers a normal request. The server runs
under a 1,024-descriptor limit. No instrument is needed: the configuration's devices are
never opened because no case may start a run.

Usage: hostile_serve_test.py DAQ_BINARY
"""
import json
import os
import re
import resource
import signal
import socket
import subprocess
import sys
import tempfile
import time

DAQ = sys.argv[1]
TMP = tempfile.mkdtemp(prefix="hostile-")
CONFIG = os.path.join(TMP, "machine.toml")
with open(CONFIG, "w") as f:
    f.write("""[machine]
name = "hostile"
[devices.laser]
driver = "ids3010"
transport = "tcp 127.0.0.1:1"
role = "laser"
[devices.air]
driver = "ptu300"
transport = "serial /dev/null 4800 7E1"
role = "air"
[test.linear]
first_mm = 0
last_mm = 100
count = 3
runs = 1
dwell_s = 3
""")

passes = 0
fails = []


def check(name, ok, detail=""):
    global passes
    if ok:
        passes += 1
    else:
        fails.append(f"{name}: {detail}")
        print(f"FAIL {name}: {detail}", flush=True)


def limit_fds(n):
    def apply():
        _, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        resource.setrlimit(resource.RLIMIT_NOFILE, (n, hard))
    return apply


class Server:
    def __init__(self, *extra, fds=1024, db="good.sqlite"):
        self.log = open(os.path.join(TMP, f"serve-{len(extra)}-{fds}.log"), "w+")
        self.proc = subprocess.Popen(
            # --check-s 0: the configuration's devices are not there (the HTTP side is tested)
            [DAQ, "serve", "-c", CONFIG, "--db", os.path.join(TMP, db), "--port", "0",
             "--check-s", "0", *extra],
            stdout=self.log, stderr=subprocess.STDOUT, preexec_fn=limit_fds(fds))
        self.port = None
        for _ in range(200):
            self.log.seek(0)
            m = re.search(r"http://127\.0\.0\.1:(\d+)/", self.log.read())
            if m:
                self.port = int(m.group(1))
                break
            if self.proc.poll() is not None:
                break
            time.sleep(0.05)
        if self.port is None:
            self.log.seek(0)
            raise SystemExit("daq serve did not start:\n" + self.log.read())

    def alive(self):
        return self.proc.poll() is None

    def stop(self):
        if self.alive():
            self.proc.send_signal(signal.SIGTERM)
        try:
            return self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            return "hung"

    def output(self):
        self.log.seek(0)
        return self.log.read()


def raw(port, data, timeout=5.0, read=True):
    """Sends bytes, returns (status, headers, body) of the answer, or (None, ...) if the
    connection was closed without one."""
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    try:
        s.sendall(data)
        if not read:
            return s
        buf = b""
        while b"\r\n\r\n" not in buf:
            chunk = s.recv(65536)
            if not chunk:
                return None, {}, b""
            buf += chunk
        head, body = buf.split(b"\r\n\r\n", 1)
        lines = head.decode("latin-1").split("\r\n")
        status = int(lines[0].split()[1])
        headers = {}
        for line in lines[1:]:
            k, _, v = line.partition(":")
            headers[k.strip().lower()] = v.strip()
        length = int(headers.get("content-length", "0"))
        while len(body) < length:
            chunk = s.recv(65536)
            if not chunk:
                break
            body += chunk
        return status, headers, body
    except (ConnectionResetError, BrokenPipeError):
        return None, {}, b""
    finally:
        if read:
            s.close()


def request(port, method, path, headers=None, body=b"", host=None):
    h = {"Host": host if host is not None else f"127.0.0.1:{port}", "Connection": "close"}
    h.update(headers or {})
    if body or method == "POST":
        h.setdefault("Content-Length", str(len(body)))
    text = f"{method} {path} HTTP/1.1\r\n" + "".join(f"{k}: {v}\r\n" for k, v in h.items())
    return raw(port, text.encode("latin-1") + b"\r\n" + body)


def json_post(port, path, body, headers=None):
    h = {"Content-Type": "application/json"}
    h.update(headers or {})
    return request(port, "POST", path, h, body)


def answers(srv, name):
    """The server still answers a normal request, and its process is alive."""
    status, _, body = request(srv.port, "GET", "/api/status")
    check(f"{name}: still answers", status == 200 and srv.alive(),
          f"status {status}, alive {srv.alive()}, {body[:200]!r}")
    return status == 200 and json.loads(body).get("running") is False


def is_json_error(name, status, headers, body, want):
    check(name, status == want, f"status {status}, expected {want}; {body[:200]!r}")
    if status is not None and status >= 400:
        ok = headers.get("content-type", "").startswith("application/json")
        try:
            ok = ok and "error" in json.loads(body)
        except ValueError:
            ok = False
        check(f"{name}: JSON error body", ok, f"{headers.get('content-type')} {body[:200]!r}")


def ws_upgrade(port, path="/ws", origin=None, host=None, extra=""):
    text = (f"GET {path} HTTP/1.1\r\nHost: {host or f'127.0.0.1:{port}'}\r\n"
            "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n")
    if origin:
        text += f"Origin: {origin}\r\n"
    text += extra + "\r\n"
    s = socket.create_connection(("127.0.0.1", port), timeout=5)
    s.sendall(text.encode())
    buf = b""
    while b"\r\n\r\n" not in buf:
        chunk = s.recv(4096)
        if not chunk:
            break
        buf += chunk
    status = int(buf.split()[1]) if buf else None
    return s, status


def closed_within(s, seconds):
    """True if the peer closes the connection within `seconds` (reading whatever comes)."""
    s.settimeout(0.2)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            if not s.recv(65536):
                return True
        except socket.timeout:
            continue
        except (ConnectionResetError, OSError):
            return True
    return False


# A process that holds N idle connections open until its stdin closes.
HOLDER = ("import socket,sys\n"
          "port, n = int(sys.argv[1]), int(sys.argv[2])\n"
          "held = []\n"
          "for _ in range(n):\n"
          "    try:\n"
          "        held.append(socket.create_connection(('127.0.0.1', port), timeout=5))\n"
          "    except OSError:\n"
          "        pass\n"
          "print('held', len(held), flush=True)\n"
          "sys.stdin.read()\n")

# ---------------------------------------------------------------------------------------------
srv = Server("--request-timeout-s", "1", "--max-connections", "256")
p = srv.port
try:
    # The page, and that it may not be framed by other sites.
    status, headers, body = request(p, "GET", "/")
    check("page", status == 200, f"status {status}")
    csp = headers.get("content-security-policy", "")
    check("page: CSP frame-ancestors 'none'", "frame-ancestors 'none'" in csp, csp)
    check("page: nosniff", headers.get("x-content-type-options") == "nosniff", str(headers))
    check("localhost Host", request(p, "GET", "/api/status", host=f"localhost:{p}")[0] == 200)

    # DNS rebinding: a foreign host name reaches no endpoint.
    for host in ("evil.example", f"evil.example:{p}", "127.0.0.1.evil.example", "", "localhost.:1"):
        status, headers, body = request(p, "GET", "/api/runs", host=host)
        is_json_error(f"foreign Host {host!r}", status, headers, body, 403)
    # Without any Host header (HTTP/1.1 requires one).
    status, headers, body = raw(p, b"GET /api/status HTTP/1.1\r\nConnection: close\r\n\r\n")
    is_json_error("no Host", status, headers, body, 403)
    answers(srv, "foreign hosts")

    # CSRF: a foreign Origin, and the CORS "simple request" with text/plain.
    for path in ("/api/runs/start", "/api/runs/stop"):
        status, headers, body = json_post(p, path, b'{"test": "linear"}',
                                          {"Origin": "http://evil.example"})
        is_json_error(f"foreign Origin {path}", status, headers, body, 403)
        status, headers, body = json_post(p, path, b'{"test": "linear"}', {"Origin": "null"})
        is_json_error(f"Origin null {path}", status, headers, body, 403)
        status, headers, body = request(p, "POST", path, {"Content-Type": "text/plain"},
                                        b'{"test": "linear"}')
        is_json_error(f"text/plain {path}", status, headers, body, 415)
        status, headers, body = request(p, "POST", path, {}, b'{"test": "linear"}')
        is_json_error(f"no Content-Type {path}", status, headers, body, 415)
    status, headers, body = request(p, "GET", "/api/status", {"Origin": "http://evil.example"})
    is_json_error("foreign Origin GET", status, headers, body, 403)
    # The page's own origin is accepted (the stop then finds no run: 409).
    status, headers, body = json_post(p, "/api/runs/stop", b"{}", {"Origin": f"http://127.0.0.1:{p}"})
    is_json_error("own Origin stop", status, headers, body, 409)
    check("no run was started by any of it", answers(srv, "CSRF"))

    # Malformed and mistyped requests: 400 with a JSON error, nothing started.
    for case in (b'{"test": 1}', b'{"test": null}', b'{"test": ["linear"]}', b"[1, 2]", b'"linear"',
                 b"not json", b'{"test": "linear"', b"", b"{}", b'{"test": "nope"}',
                 b'{"test": "linear", "extra": 1}', b'{"test": "linear\\u0000"}', b"\xff\xfe"):
        status, headers, body = json_post(p, "/api/runs/start", case)
        is_json_error(f"start {case!r}", status, headers, body, 400)
    status, headers, body = json_post(p, "/api/runs/stop", b"not json")
    is_json_error("stop with a malformed body", status, headers, body, 400)
    check("no run was started by a malformed body", answers(srv, "malformed JSON"))

    # Malformed HTTP.
    for name, data in (("garbage request line", b"\x00\x01\x02 garbage\r\n\r\n"),
                       ("bad version", b"GET / HTTP/9.9\r\nHost: 127.0.0.1\r\n\r\n"),
                       ("bad header", b"GET / HTTP/1.1\r\nHost 127.0.0.1\r\n\r\n"),
                       ("bad chunk", b"POST /api/runs/stop HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                                     b"Content-Type: application/json\r\n"
                                     b"Transfer-Encoding: chunked\r\n\r\nzz\r\n")):
        status, headers, body = raw(p, data)
        is_json_error(name, status, headers, body, 400)
    answers(srv, "malformed HTTP")

    # Size limits: a 64 KiB header, and a 100 MB body announced but never sent (refused from
    # the header, before the body is read: the answer comes although no body byte was sent).
    status, headers, body = request(p, "GET", "/api/status", {"X-Big": "a" * 65536})
    is_json_error("oversized header", status, headers, body, 431)
    status, headers, body = request(p, "POST", "/api/runs/start",
                                    {"Content-Type": "application/json",
                                     "Content-Length": "100000000"})
    is_json_error("oversized body", status, headers, body, 413)
    status, headers, body = raw(p, b"POST /api/runs/start HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                                   b"Content-Type: application/json\r\n"
                                   b"Transfer-Encoding: chunked\r\n\r\n"
                                   b"100000\r\n" + b" " * 70000)
    is_json_error("oversized chunked body", status, headers, body, 413)
    answers(srv, "size limits")

    # A slow-header client (one byte every 0.2 s) is cut off after the request timeout (1 s
    # here), long before it would finish its header. An idle connection that never sends
    # anything is opened at the same time (both wait for the same timeout).
    idle, idle_opened = raw(p, b"", read=False), time.monotonic()
    s = raw(p, b"G", read=False)
    started = time.monotonic()
    cut = False
    for byte in b"ET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: " + b"a" * 100:
        time.sleep(0.2)
        try:
            s.sendall(bytes([byte]))
        except OSError:
            cut = True
            break
        if time.monotonic() - started > 6:
            break
    cut = cut or closed_within(s, 1)
    s.close()
    check("slow header cut off", cut and time.monotonic() - started < 6,
          f"cut {cut} after {time.monotonic() - started:.1f} s")
    # The idle connection is closed too, within 4 s of being opened.
    check("idle connection closed",
          closed_within(idle, max(0.2, idle_opened + 4 - time.monotonic())))
    idle.close()
    answers(srv, "slow clients")

    # WebSocket: a foreign Origin is refused; a good one is accepted; garbage frames close it.
    s, status = ws_upgrade(p, origin="http://evil.example")
    check("WebSocket foreign Origin", status == 403, f"status {status}")
    s.close()
    s, status = ws_upgrade(p, host="evil.example")
    check("WebSocket foreign Host", status == 403, f"status {status}")
    s.close()
    s, status = ws_upgrade(p, origin=f"http://127.0.0.1:{p}")
    check("WebSocket own Origin", status == 101, f"status {status}")
    s.sendall(os.urandom(4096))
    check("WebSocket garbage closes it", closed_within(s, 5))
    s.close()
    s, status = ws_upgrade(p)
    # An unmasked frame (clients must mask) and a 2^62-byte frame length.
    s.sendall(b"\x81\x05hello" + b"\x82\xff" + (1 << 62).to_bytes(8, "big") + b"\x00" * 4)
    check("WebSocket protocol violation closes it", closed_within(s, 5))
    s.close()
    answers(srv, "WebSocket garbage")

    # 1,100 idle connections under a 1,024-descriptor limit, then a normal request.
    holders = []
    for _ in range(4):
        holders.append(subprocess.Popen(
            [sys.executable, "-c", HOLDER, str(p), "275"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True))
    held = sum(int(h.stdout.readline().split()[-1]) for h in holders)
    check("1,100 connections opened", held == 1100, f"{held}")
    t0 = time.monotonic()
    status, _, body = request(p, "GET", "/api/status")
    check("answers with 1,100 idle connections open", status == 200,
          f"status {status} after {time.monotonic() - t0:.2f} s")
    for h in holders:
        h.stdin.close()
        h.wait()
    answers(srv, "1,100 idle connections")
finally:
    rc = srv.stop()
check("serve exits cleanly on SIGTERM", rc == 0, f"exit {rc}\n{srv.output()[-2000:]}")

# The accept loop survives EMFILE: a connection cap above what 40 descriptors allow.
srv = Server("--request-timeout-s", "1", "--max-connections", "1000", fds=40)
try:
    socks = []
    for _ in range(60):
        try:
            socks.append(socket.create_connection(("127.0.0.1", srv.port), timeout=2))
        except OSError:
            break
    time.sleep(0.5)
    for s in socks:
        s.close()
    time.sleep(0.3)
    status, _, _ = request(srv.port, "GET", "/api/status")
    check("answers after EMFILE", status == 200, f"status {status}")
    answers(srv, "EMFILE")
finally:
    rc = srv.stop()
check("serve (EMFILE) exits cleanly", rc == 0, f"exit {rc}\n{srv.output()[-2000:]}")

# A database that cannot be opened: 500 with a JSON error, the server keeps running.
with open(os.path.join(TMP, "bad.sqlite"), "wb") as f:
    f.write(b"this is not a database" * 100)
srv = Server(db="bad.sqlite")
try:
    status, headers, body = request(srv.port, "GET", "/api/runs")
    is_json_error("bad database", status, headers, body, 500)
    check("bad database: the message names the file", b"bad.sqlite" in body, f"{body[:300]!r}")
    answers(srv, "bad database")
finally:
    rc = srv.stop()
check("serve (bad database) exits cleanly", rc == 0, f"exit {rc}\n{srv.output()[-2000:]}")

# With --token: every endpoint and the WebSocket; Bearer (any case) or ?token=; checked
# before the body is read.
srv = Server("--token", "s3cret-token")
p = srv.port
try:
    for name, path, headers, want in (
            ("no token", "/api/status", {}, 401),
            ("wrong token", "/api/status", {"Authorization": "Bearer s3cret-tokeN"}, 401),
            ("short token", "/api/status", {"Authorization": "Bearer s"}, 401),
            ("long token", "/api/status", {"Authorization": "Bearer s3cret-token-and-more"}, 401),
            ("empty token", "/api/status", {"Authorization": "Bearer "}, 401),
            ("other scheme", "/api/status", {"Authorization": "Basic s3cret-token"}, 401),
            ("page without token", "/", {}, 401),
            ("Bearer", "/api/status", {"Authorization": "Bearer s3cret-token"}, 200),
            ("bearer", "/api/status", {"Authorization": "bearer s3cret-token"}, 200),
            ("BEARER", "/", {"Authorization": "BEARER s3cret-token"}, 200),
            ("query", "/?token=s3cret-token", {}, 200),
            ("query among others", "/api/status?a=1&token=s3cret-token&b=2", {}, 200),
            ("query prefix", "/api/status?xtoken=s3cret-token", {}, 401),
            ("query wrong", "/api/status?token=s3cret", {}, 401)):
        status, hdrs, body = request(p, "GET", path, headers)
        check(f"token: {name}", status == want, f"status {status}, expected {want}")
    # A 100 MB body announced without a token: 401 at once, nothing read.
    status, _, _ = request(p, "POST", "/api/runs/start",
                           {"Content-Type": "application/json", "Content-Length": "100000000"})
    check("token before the body", status == 401, f"status {status}")
    s, status = ws_upgrade(p)
    check("WebSocket without token", status == 401, f"status {status}")
    s.close()
    s, status = ws_upgrade(p, "/ws?token=s3cret-token")
    check("WebSocket with ?token=", status == 101, f"status {status}")
    s.close()
    s, status = ws_upgrade(p, extra="Authorization: Bearer s3cret-token\r\n")
    check("WebSocket with Bearer", status == 101, f"status {status}")
    s.close()
    status, _, _ = request(p, "GET", "/api/status", {"Authorization": "Bearer s3cret-token"})
    check("token: still answers", status == 200 and srv.alive())
finally:
    rc = srv.stop()
check("serve (token) exits cleanly", rc == 0, f"exit {rc}\n{srv.output()[-2000:]}")

print(f"{passes} passed, {len(fails)} failed")
sys.exit(1 if fails else 0)
