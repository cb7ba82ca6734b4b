#!/usr/bin/env python3
"""Hostile clients against a real `daq serve` on loopback (issues 15 and 27).

Every case sends what a hostile web page, a DNS-rebinding attacker, a confused script or a
descriptor-exhausting client would send, asserts the status code (or that the connection is
closed), and then asserts that the server still answers a normal request. The server runs
under a 1,024-descriptor limit. No instrument is needed: the configuration's devices are
never opened because no case may start a run.

The lock-out cases (issue 27): clients that keep their sockets after a 401, slow POST bodies
and WebSockets that fill the connection cap, each refilled as the server closes them; while
they run, the page's own requests (GET /, GET /api/status, the Stop POST, its WebSocket) must
all be answered. Then the set-up's devices (only the configuration's and --allow-device's are
opened), the read-only database, the report's and the page's Content-Security-Policy, HEAD,
/api/setup/program's fields and the IPv6 URL.

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


SERVERS = 0


class Server:
    def __init__(self, *extra, fds=1024, db="good.sqlite", prefix=(), url=r"127\.0\.0\.1"):
        global SERVERS
        SERVERS += 1
        self.log = open(os.path.join(TMP, f"serve-{SERVERS}.log"), "w+")
        self.proc = subprocess.Popen(
            # --check-s 0: the configuration's devices are not there (the HTTP side is tested)
            [*prefix, DAQ, "serve", "-c", CONFIG, "--db", os.path.join(TMP, db), "--port", "0",
             "--check-s", "0", *extra],
            stdout=self.log, stderr=subprocess.STDOUT, preexec_fn=limit_fds(fds))
        self.port = None
        for _ in range(200):
            self.log.seek(0)
            m = re.search(r"http://" + url + r":(\d+)/", self.log.read())
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

# ---------------------------------------------------------------------------------------------
# Lock-out (issue 27): hostile clients fill the connection cap and refill it as the server
# closes their connections; the page's own requests must all get through meanwhile.

# Holds N connections of one kind to the server, reopening each the server closes (after
# DELAY s), until its stdin closes (or 90 s). Kinds: "refused" (an unauthorised request, its
# 401 read, the socket kept, a byte sent every 0.25 s to see when the server really closed
# it), "slowbody" (a POST announcing 4 KiB, one byte every 0.25 s), "websocket" (a WebSocket
# without Origin, its messages read). Prints "opened N" once the first N are opened.
LOCKER = r"""
import selectors, socket, sys, time
port, n, mode, delay = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], float(sys.argv[4])
host = "127.0.0.1:%d" % port
OPEN = {
    "refused": "GET /api/status HTTP/1.1\r\nHost: %s\r\n\r\n" % host,
    "slowbody": "POST /api/runs/stop HTTP/1.1\r\nHost: %s\r\nContent-Type: application/json\r\n"
                "Content-Length: 4096\r\n\r\n{" % host,
    "websocket": "GET /ws HTTP/1.1\r\nHost: %s\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                 "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n"
                 % host,
}[mode].encode()
sel = selectors.DefaultSelector()
sel.register(sys.stdin, selectors.EVENT_READ, None)
live, due, reopened = {}, [], 0
def connect():
    try:
        s = socket.create_connection(("127.0.0.1", port), timeout=2)
        s.sendall(OPEN)
        s.setblocking(False)
    except OSError:
        return False
    live[s] = time.monotonic() + 0.25
    sel.register(s, selectors.EVENT_READ, s)
    return True
def lost(s):
    try:
        sel.unregister(s)
    except (KeyError, ValueError):
        pass
    live.pop(s, None)
    s.close()
    due.append(time.monotonic() + delay)
opened = sum(connect() for _ in range(n))
print("opened", opened, flush=True)
deadline = time.monotonic() + 90
while time.monotonic() < deadline:
    now = time.monotonic()
    for t in [t for t in due if t <= now]:
        due.remove(t)
        if connect():
            reopened += 1
        else:
            due.append(now + delay)
    for key, _ in sel.select(timeout=0.05):
        if key.data is None:
            if not sys.stdin.readline():
                print("reopened", reopened, flush=True)
                sys.exit(0)
            continue
        s = key.data
        try:
            data = s.recv(65536)
        except BlockingIOError:
            continue
        except OSError:
            lost(s)
            continue
        if not data:
            if mode == "refused":
                sel.unregister(s)  # half-closed after the answer: the socket is kept
            else:
                lost(s)
    if mode != "websocket":
        for s, t in list(live.items()):
            if t <= now:
                try:
                    s.send(b"x")
                    live[s] = now + 0.25
                except BlockingIOError:
                    pass
                except OSError:
                    lost(s)
print("reopened", reopened, flush=True)
"""


def page_ws(port, token=None, timeout=3.0):
    """The page's WebSocket: 101 and its first state message (a text frame) within timeout."""
    path = "/ws" + (f"?token={token}" if token else "")
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    try:
        s.sendall((f"GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
                   "Connection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
                   "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                   f"Origin: http://127.0.0.1:{port}\r\n\r\n").encode())
        buf = b""
        while b"\r\n\r\n" not in buf or len(buf) <= buf.index(b"\r\n\r\n") + 4:
            chunk = s.recv(65536)
            if not chunk:
                return False
            buf += chunk
        head, frame = buf.split(b"\r\n\r\n", 1)
        return head.split()[1] == b"101" and frame[0] == 0x81
    finally:
        s.close()


def page_gets_through(port, rounds, token=None):
    """Each round: GET /, GET /api/status, the Stop POST (409: no run), the WebSocket, each on
    a new connection as a browser under attack would open. Returns (served, tried, worst s)."""
    auth = {"Authorization": f"Bearer {token}"} if token else {}
    own = {"Origin": f"http://127.0.0.1:{port}"}
    tries = (("GET /", lambda: request(port, "GET", "/", auth)[0] == 200),
             ("GET /api/status", lambda: request(port, "GET", "/api/status", auth)[0] == 200),
             ("Stop", lambda: json_post(port, "/api/runs/stop", b"{}", {**auth, **own})[0] == 409),
             ("WebSocket", lambda: page_ws(port, token)))
    served, worst, failed = 0, 0.0, []
    for _ in range(rounds):
        for name, attempt in tries:
            t0 = time.monotonic()
            try:
                ok = attempt()
            except OSError:
                ok = False
            took = time.monotonic() - t0
            worst = max(worst, took)
            if ok and took < 3:
                served += 1
            else:
                failed.append(name)
        time.sleep(0.1)
    return served, rounds * len(tries), worst, failed


def lockout(name, srv, mode, count, delay, token=None, rounds=10):
    locker = subprocess.Popen([sys.executable, "-c", LOCKER, str(srv.port), str(count), mode,
                               str(delay)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                              text=True)
    try:
        opened = int(locker.stdout.readline().split()[-1])
        check(f"{name}: {count} hostile connections opened", opened == count, f"{opened}")
        time.sleep(0.5)  # they are all being refilled by now
        served, tried, worst, failed = page_gets_through(srv.port, rounds, token)
    finally:
        locker.stdin.close()
        out = locker.stdout.read()
        locker.wait(timeout=10)
    print(f"{name}: the page's requests served {served} of {tried}, the slowest in {worst:.2f} s; "
          f"hostile connections reopened: {out.split()[-1] if out.split() else '?'}", flush=True)
    check(f"{name}: every request of the page served", served == tried,
          f"{served} of {tried} (failed: {sorted(set(failed))}), slowest {worst:.2f} s")
    if token is None:
        answers(srv, name)


# With --token on loopback (the default 10 s request timeout and 256 connections): 264 clients
# that keep their sockets after the 401.
srv = Server("--token", "s3cret-token")
try:
    # A refused connection is closed whole, soon, even if the client keeps sending.
    s = raw(srv.port, f"GET /api/status HTTP/1.1\r\nHost: 127.0.0.1:{srv.port}\r\n\r\n".encode(),
            read=False)
    t0, cut = time.monotonic(), False
    while time.monotonic() - t0 < 6 and not cut:
        time.sleep(0.2)
        try:
            s.send(b"x")
        except OSError:
            cut = True
    s.close()
    check("after a 401 the connection is closed within 4 s", cut and time.monotonic() - t0 < 4,
          f"closed {cut} after {time.monotonic() - t0:.1f} s")
    lockout("256 clients keeping their sockets after a 401", srv, "refused", 264, 0.2,
            token="s3cret-token")
    status, _, _ = request(srv.port, "GET", "/api/status", {"Authorization": "Bearer s3cret-token"})
    check("after the 401 clients: still answers", status == 200 and srv.alive(), f"{status}")
finally:
    rc = srv.stop()
check("serve (401 clients) exits cleanly", rc == 0, f"exit {rc}\n{srv.output()[-2000:]}")

# Slow POST bodies on loopback, within one address' cap and then the overall cap.
for label, extra in (("per address", ()), ("overall", ("--max-connections-per-client", "100000"))):
    srv = Server(*extra)
    try:
        lockout(f"slow POST bodies ({label} cap)", srv, "slowbody", 264, 0.2)
    finally:
        rc = srv.stop()
    check(f"serve (slow bodies, {label}) exits cleanly", rc == 0,
          f"exit {rc}\n{srv.output()[-2000:]}")

# WebSockets filling the cap (without the page's Origin, reading what they get).
srv = Server()
try:
    lockout("WebSocket clients filling the cap", srv, "websocket", 264, 0.5)
finally:
    rc = srv.stop()
check("serve (WebSocket flood) exits cleanly", rc == 0, f"exit {rc}\n{srv.output()[-2000:]}")

# A slow body is cut off like a slow header: the header and the body within the request
# timeout.
srv = Server("--request-timeout-s", "1")
try:
    s = raw(srv.port, (f"POST /api/runs/stop HTTP/1.1\r\nHost: 127.0.0.1:{srv.port}\r\n"
                       "Content-Type: application/json\r\nContent-Length: 200\r\n\r\n").encode(),
            read=False)
    t0, cut = time.monotonic(), False
    for _ in range(30):
        time.sleep(0.2)
        try:
            s.sendall(b" ")
        except OSError:
            cut = True
            break
    cut = cut or closed_within(s, 1)
    s.close()
    check("slow body cut off", cut and time.monotonic() - t0 < 4,
          f"cut {cut} after {time.monotonic() - t0:.1f} s")
    answers(srv, "slow body")
finally:
    rc = srv.stop()

# ---------------------------------------------------------------------------------------------
# The set-up names only devices the operator allowed (issue 27): a set-up naming another TCP
# port or a terminal is refused (403, the device and the option that would allow it named)
# before anything is opened; the listening socket sees no connection.
import select  # noqa: E402


def connection_within(listener, seconds):
    r, _, _ = select.select([listener], [], [], seconds)
    if not r:
        return False
    conn, _ = listener.accept()
    conn.close()
    return True


listener = socket.socket()
listener.bind(("127.0.0.1", 0))
listener.listen(8)
lport = listener.getsockname()[1]
srv = Server()
p = srv.port
try:
    status, _, body = request(p, "GET", "/api/setup")
    setup = json.loads(body)["setup"]
    own = json.loads(json.dumps(setup))
    setup["devices"]["laser"]["transport"] = f"tcp 127.0.0.1:{lport}"
    # A body nested 30 000 deep (under the 64 KiB body limit) is refused (400) before anything
    # recurses into it, at every endpoint that reads JSON, and the server still answers.
    deep = b'{"setup": ' + b'[' * 30000 + b']' * 30000 + b'}'
    for path in ("/api/setup/apply", "/api/setup/check", "/api/setup/program", "/api/runs/start"):
        status, headers, body = json_post(p, path, deep)
        check(f"a body nested 30 000 deep at {path} is refused", status == 400, f"{status} {body[:200]!r}")
    status, _, _ = request(p, "GET", "/api/status")
    check("the server answers after the deep bodies", status == 200, f"{status}")
    status, headers, body = json_post(p, "/api/setup/apply", json.dumps({"setup": setup}).encode())
    is_json_error("set-up naming another TCP port", status, headers, body, 403)
    j = json.loads(body) if status == 403 else {}
    check("the refusal names the device and how to allow it",
          j.get("device") == "devices.laser" and j.get("allow") == f"--allow-device 127.0.0.1:{lport}"
          and "devices.laser" in j.get("error", "") and "--allow-device" in j.get("error", ""),
          f"{body[:400]!r}")
    check("nothing connected to the port it named", not connection_within(listener, 1.5))
    terminal = json.loads(json.dumps(own))
    terminal["devices"]["air"]["transport"] = "serial /dev/tty0 9600 8N1"
    status, headers, body = json_post(p, "/api/setup/apply",
                                      json.dumps({"setup": terminal}).encode())
    is_json_error("set-up naming /dev/tty0", status, headers, body, 403)
    check("the /dev/tty0 refusal says how to allow it",
          b"--allow-device /dev/tty0" in body and b"devices.air" in body, f"{body[:400]!r}")
    # The check shows it at the field, as the loader's problems.
    status, _, body = json_post(p, "/api/setup/check", json.dumps({"setup": setup}).encode())
    problems = json.loads(body).get("problems", []) if status == 200 else []
    check("the check names the field", status == 200 and not json.loads(body)["ok"] and
          any(q["key"] == "devices.laser.transport" for q in problems), f"{status} {body[:400]!r}")
    # The configuration's own devices may be applied again.
    status, _, body = json_post(p, "/api/setup/apply", json.dumps({"setup": own}).encode())
    check("the configuration's own devices are accepted", status == 200, f"{status} {body[:300]!r}")
finally:
    rc = srv.stop()
srv = Server("--allow-device", f"127.0.0.1:{lport}", "--allow-device", "/dev/ttyUSB*")
try:
    status, _, body = json_post(srv.port, "/api/setup/apply", json.dumps({"setup": setup}).encode())
    check("--allow-device HOST:PORT allows it", status == 200, f"{status} {body[:300]!r}")
    # (So the check above could see a connection: the allowed device is opened at once.)
    check("the allowed device is opened", connection_within(listener, 5))
finally:
    rc = srv.stop()
listener.close()
status = subprocess.run([DAQ, "serve", "-c", CONFIG, "--port", "0", "--allow-device", "ttyUSB0"],
                        capture_output=True, text=True, timeout=20)
check("a malformed --allow-device is refused naming it", status.returncode == 2 and
      "--allow-device 'ttyUSB0'" in status.stderr, f"{status.returncode} {status.stderr[-300:]}")

# ---------------------------------------------------------------------------------------------
# Reads open the database read-only (issue 27): a GET at a mistyped --db creates nothing; a
# database of the schema-1 code is read as it is (never migrated by a read), also on a
# read-only medium (a tmpfs remounted read-only in a private mount namespace, where allowed).
SCHEMA1 = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "storage",
                       "schema1.sqlite")
srv = Server(db="typo/site.sqlite")
try:
    for path in ("/api/runs", "/api/machines", "/api/runs/1", "/reports/run-1.html"):
        status, _, body = request(srv.port, "GET", path)
        check(f"mistyped --db: GET {path}", status in (200, 404), f"{status} {body[:200]!r}")
    status, _, body = request(srv.port, "GET", "/api/runs")
    check("mistyped --db: no runs", status == 200 and json.loads(body)["runs"] == [], f"{body[:200]!r}")
    check("mistyped --db: nothing created", not os.path.exists(os.path.join(TMP, "typo")))
finally:
    srv.stop()
import shutil  # noqa: E402
shutil.copy(SCHEMA1, os.path.join(TMP, "old.sqlite"))
srv = Server(db="old.sqlite")
try:
    status, _, body = request(srv.port, "GET", "/api/runs")
    check("schema-1 database: its runs listed", status == 200 and
          [r["id"] for r in json.loads(body)["runs"]] == [1, 2], f"{status} {body[:300]!r}")
    status, _, body = request(srv.port, "GET", "/api/runs/1")
    check("schema-1 database: a run read", status == 200, f"{status} {body[:300]!r}")
finally:
    srv.stop()
with open(SCHEMA1, "rb") as a, open(os.path.join(TMP, "old.sqlite"), "rb") as b:
    check("schema-1 database unchanged by the reads", a.read() == b.read())
if subprocess.run(["unshare", "-rm", "true"], capture_output=True).returncode == 0:
    mnt = os.path.join(TMP, "ro")
    os.makedirs(mnt)
    script = (f"set -e; mount -t tmpfs -o size=2m tmpfs {mnt}; cp {SCHEMA1} {mnt}/site.sqlite; "
              f"mount -o remount,ro {mnt}; exec \"$@\"")
    srv = Server(prefix=("unshare", "-rm", "bash", "-c", script, "ro"),
                 db=os.path.join(mnt, "site.sqlite"))
    try:
        for path in ("/api/runs", "/api/runs/1", "/api/machines", "/reports/run-1.html"):
            status, _, body = request(srv.port, "GET", path)
            check(f"read-only medium: GET {path}", status == 200, f"{status} {body[:300]!r}")
    finally:
        srv.stop()
else:
    print("(read-only medium not tried: unshare -rm is not allowed here; the unchanged schema-1 "
          "file above shows that reads write nothing)")

# ---------------------------------------------------------------------------------------------
# The report is an inert document, the page runs only its own script; HEAD; the program's
# fields; the IPv6 URL (issue 27).
shutil.copy(SCHEMA1, os.path.join(TMP, "reports.sqlite"))
srv = Server(db="reports.sqlite")
p = srv.port
try:
    status, headers, body = request(p, "GET", "/reports/run-1.html")
    csp = headers.get("content-security-policy", "")
    check("report served", status == 200 and b"<html" in body[:2000].lower(),
          f"{status} {body[:200]!r}")
    for directive in ("default-src 'none'", "script-src 'none'", "frame-src 'none'",
                      "base-uri 'none'", "form-action 'none'", "frame-ancestors 'none'", "sandbox"):
        check(f"report CSP {directive}", directive in csp, csp)
    check("report: nosniff", headers.get("x-content-type-options") == "nosniff", str(headers))
    status, headers, body = request(p, "GET", "/")
    csp = headers.get("content-security-policy", "")
    m = re.search(r"script-src 'nonce-([A-Za-z0-9+/=]+)'", csp)
    check("page CSP: script by nonce only", m is not None and "unsafe-inline" not in
          csp.split("script-src")[1].split(";")[0] and "default-src 'none'" in csp, csp)
    if m:
        scripts = re.findall(rb"<script[^>]*>", body)
        check("page: every script carries the nonce", scripts and all(
            f'nonce="{m.group(1)}"'.encode() in t for t in scripts), f"{scripts[:5]}")
    # HEAD / as GET without the body.
    s = raw(p, f"HEAD / HTTP/1.1\r\nHost: 127.0.0.1:{p}\r\nConnection: close\r\n\r\n".encode(),
            read=False)
    got = b""
    while True:
        chunk = s.recv(65536)
        if not chunk:
            break
        got += chunk
    s.close()
    head, _, rest = got.partition(b"\r\n\r\n")
    length = re.search(rb"(?i)content-length: *(\d+)", head)
    check("HEAD / is 200 with GET's length and no body", head.startswith(b"HTTP/1.1 200") and
          length and int(length.group(1)) == len(body) and rest == b"", f"{head[:300]!r} {len(rest)}")
    # /api/setup/program: a mistyped or unknown field is refused naming it.
    status, _, body = request(p, "GET", "/api/setup")
    setup = json.loads(body)["setup"]
    for field, value in (("test", 1), ("test", "lineal"), ("dialect", ["fanuc"]),
                         ("dialect", "haas"), ("test", None)):
        status, headers, body = json_post(p, "/api/setup/program",
                                          json.dumps({"setup": setup, field: value}).encode())
        is_json_error(f"program {field}={value!r}", status, headers, body, 400)
        check(f"program {field}={value!r}: the field named", f'"{field}"'.encode() in
              body.replace(b'\\"', b'"'), f"{body[:300]!r}")
    status, headers, body = json_post(p, "/api/setup/program", json.dumps(
        {"setup": setup, "test": "linear", "dialect": "heidenhain"}).encode())
    check("program with good fields", status == 200 and headers.get("content-type", "").startswith(
        "text/plain"), f"{status} {body[:200]!r}")
finally:
    srv.stop()
srv = Server("--address", "::1", url=r"\[::1\]")
try:
    s = socket.create_connection(("::1", srv.port), timeout=5)
    s.sendall(f"GET /api/status HTTP/1.1\r\nHost: [::1]:{srv.port}\r\nConnection: close\r\n\r\n".encode())
    check("IPv6: http://[::1]:PORT/ printed and served", s.recv(100).startswith(b"HTTP/1.1 200"))
    s.close()
finally:
    srv.stop()
status = subprocess.run([DAQ, "serve", "-c", CONFIG, "--port", "0", "--address", "0.0.0.0"],
                        capture_output=True, text=True, timeout=20)
check("no doubled prefix in an error", status.returncode == 2 and "daq serve: daq serve" not in
      status.stderr and "needs --token" in status.stderr, status.stderr[-300:])

print(f"{passes} passed, {len(fails)} failed")
if not fails:  # a failure keeps the servers' logs and stores for whoever looks at it
    shutil.rmtree(TMP, ignore_errors=True)
sys.exit(1 if fails else 0)
