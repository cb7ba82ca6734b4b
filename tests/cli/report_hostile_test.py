"""Reports are inert documents (issue 27): hostile names reach every report by the ways a name
really gets into the database, and no report can run script or carry a local file.

The names: a run made with a configuration (daq sim's shop) whose machine, make, customer,
site, operator, notes, campaign and instruments' serial numbers and certificates are markup
(`</style><script>`, `"><img onerror>`, `<iframe src=file://...>`, `</title>`); a replayed
capture whose header's configuration (docs/capture-format.md) names the machine and campaign so;
an imported Renishaw .rtx whose `Machine:` and `Owner:` lines (the latter a plot's title and
legend) do the same; a machine model file with a hostile name; a five-axis ballbar run whose simulated machine and
control models have hostile paths. Each report (run, campaign, comparison, as found / as
left, the model's page) is then
  (a) parsed with html.parser: only the report's own elements, no event-handler attribute, the
      Content-Security-Policy first in <head>, one <style> block with no `<` in it, and the
      names in the text verbatim;
  (b) rendered by headless Chromium (--dump-dom): the scripts the names hold would change
      document.title or add an element; neither happened;
  (c) printed to PDF by `daq report --format pdf`: a local file the names point at (a unique
      marker in a temporary file) is not in the PDF's text, the name itself is.
Then how the PDF is printed: through a stand-in browser ($CALDAQ_CHROMIUM), which records what
it sees: a private directory (0700) holding only the report, no network, no shell (an output
path with a quote and `$(...)` is only a path), the directory removed afterwards.
Usage: report_hostile_test.py DAQ_BINARY"""
import html
import html.parser
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import uuid

from demo_runs import demo_runs

DAQ = os.path.abspath(sys.argv[1])
TMP = tempfile.mkdtemp(prefix="caldaq-hostile-")
failures = []
passes = 0


def check(name, ok, detail=""):
    global passes
    if ok:
        passes += 1
    else:
        failures.append(name)
        print(f"FAIL {name}: {detail}"[:2000])


def daq(*args, **kw):
    return subprocess.run([DAQ, *args], cwd=TMP, capture_output=True, text=True, timeout=300, **kw)


# --- the hostile names -----------------------------------------------------------------------
MARKER = "CALDAQ-LOCAL-FILE-" + uuid.uuid4().hex[:12]
SECRET = os.path.join(TMP, "secret.txt")
with open(SECRET, "w") as f:
    f.write(f"{MARKER}\n")
SECRET_URL = "file://" + SECRET
# A script that ran leaves a trace in the DOM Chromium dumps: an element <xss-ran> or a title.
RUN_JS = "document.title='XSS';document.body.appendChild(document.createElement('xss-ran'))"
names = {
    "machine": f"M</style><script>{RUN_JS}</script><iframe src={SECRET_URL}></iframe>",
    "customer": f'C"><img src=x onerror="{RUN_JS}"><object data={SECRET_URL}></object>',
    "site": f"S</title><script>{RUN_JS}</script>",
    "operator": f"O<link rel=stylesheet href={SECRET_URL}><embed src={SECRET_URL}>",
    "notes": f"N<iframe src={SECRET_URL}></iframe><img src={SECRET_URL}>",
    "campaign": f"K</style></title><script>{RUN_JS}</script><iframe src={SECRET_URL}>",
    "serial": f"I<svg onload=\"{RUN_JS}\"></svg><iframe srcdoc='<b>x</b>'>",
    "make": "Mk'\"\\</style>&amp;",
}
for k, v in names.items():
    assert len(v.encode()) <= 200, (k, len(v))  # the configuration's limit for a name

# The report's own elements (HTML and PLplot's SVG); anything else came from data.
EXPECTED_TAGS = {
    "html", "head", "meta", "title", "style", "body", "h1", "h2", "h3", "h4", "p", "table",
    "thead", "tbody", "tr", "th", "td", "span", "strong", "em", "sub", "sup", "code", "figure",
    "figcaption", "footer", "div", "a", "br", "ul", "li",
    "svg", "g", "path", "polyline", "polygon", "text", "tspan", "clippath", "defs", "rect", "line",
    "circle", "ellipse", "desc"}

# --- the runs: a demo, a replayed capture with a hostile header, an imported .rtx ------------
def make_demo():
    r = daq("demo", "--quiet", "--db", "demo.sqlite", "--capture", "demo.cdq")
    assert r.returncode == 0, r.stdout + r.stderr


demo_cdq = demo_runs(TMP, make_demo)


def crc32c(data, crc=0):
    crc ^= 0xFFFFFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ (0x82F63B78 & -(crc & 1))
    return crc ^ 0xFFFFFFFF


def rewrite_capture(src, dst, edit):
    """The capture with its header JSON edited (docs/capture-format.md: magic, versions, length,
    text, CRC-32C of bytes 8 .. 16 + H - 1), the blocks after it unchanged."""
    data = open(src, "rb").read()
    (length,) = struct.unpack_from("<I", data, 12)
    header = json.loads(data[16:16 + length])
    edit(header)
    text = json.dumps(header).encode()
    head = data[8:12] + struct.pack("<I", len(text)) + text
    out = data[:8] + head + struct.pack("<I", crc32c(head)) + data[20 + length:]
    open(dst, "wb").write(out)


def hostile_header(h):  # the capture header's configuration names the machine and campaign
    h["config"]["machine"] = names["machine"]
    h["config"]["campaign"] = names["campaign"]


rewrite_capture(demo_cdq, os.path.join(TMP, "hostile.cdq"), hostile_header)
r = daq("replay", "hostile.cdq", "--db", "demo.sqlite")
m = re.search(r"into run (\d+)", r.stdout + r.stderr)
check("replay_hostile_capture", r.returncode == 0 and m, r.stdout + r.stderr)
REPLAYED = m.group(1) if m else "3"


def toml_str(v):
    return json.dumps(v, ensure_ascii=False)  # a TOML basic string: JSON's escapes


def hostile_config(text):
    """daq sim's configuration with every name of the report's identity tables hostile."""
    text = re.sub(r'^campaign = .*$', lambda _: f"campaign = {toml_str(names['campaign'])}\n"
                  f"operator = {toml_str(names['operator'])}", text, count=1, flags=re.M)
    text = re.sub(r'^(\[machine\]\n)name = .*$', lambda mm: f"{mm.group(1)}name = "
                  f"{toml_str(names['machine'])}\nmake = {toml_str(names['make'])}", text,
                  count=1, flags=re.M)
    text = re.sub(r'^serial_number = .*$', lambda _: f"serial_number = {toml_str(names['serial'])}"
                  f"\ncertificate = {toml_str(names['notes'])}", text, flags=re.M)
    return (text + f"\n[customer]\nname = {toml_str(names['customer'])}\n"
            f"site = {toml_str(names['site'])}\n\n[conditions]\nnotes = {toml_str(names['notes'])}\n")


# A run made with a hostile configuration: daq sim's shop (run_linear_test.sh, 2 runs over 3
# targets, about 6 s), its configuration given the names.
sim = subprocess.Popen([DAQ, "sim", "--test", "linear", "--runs", "2", "--targets", "3", "--speed",
                        "5", "--start-after-s", "2", "-o", "sim.toml"], cwd=TMP,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
try:
    for _ in range(100):
        if os.path.exists(os.path.join(TMP, "sim.toml")) and os.path.getsize(
                os.path.join(TMP, "sim.toml")):
            break
        time.sleep(0.1)
    with open(os.path.join(TMP, "hostile.toml"), "w") as f:
        f.write(hostile_config(open(os.path.join(TMP, "sim.toml")).read()))
    r = daq("run", "linear", "-c", "hostile.toml", "--db", "demo.sqlite")
finally:
    sim.kill()
    sim.wait()
m = re.search(r"^run (\d+) stored \(complete\)", r.stdout, re.M)
check("run_hostile_configuration", r.returncode == 0 and m, r.stdout[-1500:] + r.stderr)
RUN = m.group(1) if m else "4"

# An .rtx (cli_test.sh): three float64 samples after a header naming the machine and the owner.
rtx_head = ("HEADER::\r\nOwner: O<script>" + RUN_JS + "</script>\r\nVersion no: 4.13\r\n"
            "File Type: Linear\r\nSample rate: 50000\r\nSample no: 3\r\nActual sample rate: 1000\r\n"
            "Machine: " + names["machine"] + "\r\nSerial No: 99\r\nAxis: Y\r\nData:\r\n")
with open(os.path.join(TMP, "hostile.rtx"), "wb") as f:
    f.write(rtx_head.encode() + struct.pack("<3d", 1.0, -2.5, 0.125) + b"\r\nEOF::\r\n")
r = daq("import", "rtx", "hostile.rtx", "--db", "rtx.sqlite")
check("import_hostile_rtx", r.returncode == 0, r.stdout + r.stderr)

# A machine model whose name is markup.
model = json.load(open(os.path.join(os.path.dirname(__file__), "..", "data", "model",
                                    "square50.json")))
model["machine"] = names["machine"]
json.dump(model, open(os.path.join(TMP, "hostile-model.json"), "w"))

# A five-axis ballbar run (issue 36) whose models' paths are markup: the run names its machine
# by the simulated truth's path and records the control's kinematics by its path (each '/' of a
# name a directory here).
MODELS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "model")
bb5x_models = {"truth": names["machine"] + ".json", "control": names["make"] + ".json"}
for which, path in bb5x_models.items():
    os.makedirs(os.path.join(TMP, os.path.dirname(path)), exist_ok=True)
    shutil.copy(os.path.join(MODELS, f"trunnion_{'truth' if which == 'truth' else 'nominal'}.json"),
                os.path.join(TMP, path))
r = daq("model", "ballbar5x-run", bb5x_models["truth"], "--control", bb5x_models["control"],
        "--db", "bb5x.sqlite", "--ball-mm", "150", "0", "-250", "--setups", "radial", "axial")
check("ballbar5x_hostile_models", r.returncode == 0, r.stdout[-1500:] + r.stderr)

# --- the reports --------------------------------------------------------------------------------
reports = {
    "run": (["report", RUN, "--db", "demo.sqlite"], ["machine", "customer", "site", "operator",
                                                     "notes", "campaign", "serial", "make"]),
    "replayed": (["report", REPLAYED, "--db", "demo.sqlite"], ["machine", "campaign"]),
    "rtx": (["report", "1", "--db", "rtx.sqlite"], ["machine"]),
    "campaign": (["report", "--campaign", names["campaign"], "--db", "demo.sqlite"],
                 ["machine", "customer", "campaign"]),
    "compare": (["report", "--compare", "1", RUN, "--db", "demo.sqlite"], []),
    "asfound": (["report", "--as-found", "1", "--as-left", RUN, "--db", "demo.sqlite"],
                ["machine", "customer", "operator"]),
    "ballbar5x": (["report", "1", "--db", "bb5x.sqlite"], ["machine", "make"]),
}


class Parsed(html.parser.HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tags, self.handlers, self.order, self.text = set(), [], [], []
        self.style, self.title, self.in_style, self.in_title = [], [], False, False

    def handle_starttag(self, tag, attrs):
        self.tags.add(tag)
        self.order.append((tag, dict(attrs)))
        self.handlers += [(tag, a) for a, _ in attrs if a.startswith("on") or a == "srcdoc"]
        self.in_style, self.in_title = tag == "style", tag == "title"

    def handle_startendtag(self, tag, attrs):
        self.handle_starttag(tag, attrs)

    def handle_endtag(self, tag):
        self.in_style = self.in_title = False

    def handle_data(self, data):
        (self.style if self.in_style else self.title if self.in_title else self.text).append(data)


def check_html(name, path, expect_names):
    doc = open(path, encoding="utf-8").read()
    p = Parsed()
    p.feed(doc)
    check(f"{name}_tags", p.tags <= EXPECTED_TAGS, sorted(p.tags - EXPECTED_TAGS))
    check(f"{name}_no_handlers", not p.handlers, p.handlers[:5])
    for bad in ("<script", "<iframe", "<object", "<embed", "<img", "<link"):
        check(f"{name}_no_{bad[1:]}", bad not in doc.lower(), bad)
    head = [t for t in p.order if t[0] != "html"]
    check(f"{name}_csp_first", head and head[0][0] == "head" and head[1][0] == "meta" and
          head[1][1].get("http-equiv") == "Content-Security-Policy" and
          "script-src 'none'" in head[1][1].get("content", "") and
          "frame-src 'none'" in head[1][1].get("content", ""), head[:2])
    check(f"{name}_one_style", doc.count("<style>") == 1 and doc.count("</style>") == 1,
          doc.count("</style>"))
    style = "".join(p.style)
    check(f"{name}_style_inert", "<" not in style, style[-400:])
    text = "".join(p.text) + "".join(p.title)
    for n in expect_names:
        check(f"{name}_shows_{n}", names[n] in text, names[n])
    return doc


def dump_dom(path):
    """The DOM after Chromium loaded the page, scripts allowed (the report must not have any)."""
    prof = tempfile.mkdtemp(dir=TMP, prefix="profile-")
    r = subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu",
                        f"--user-data-dir={prof}", "--no-first-run", "--virtual-time-budget=2000",
                        "--dump-dom", "file://" + path], capture_output=True, text=True,
                       timeout=120)
    return r.stdout


for name, (args, expect) in reports.items():
    out = os.path.join(TMP, f"{name}.html")
    r = daq(*args, "-o", out)
    check(f"{name}_written", r.returncode == 0, r.stdout + r.stderr)
    if r.returncode != 0:
        continue
    doc = check_html(name, out, expect)
    title = html.unescape(re.search(r"<title>(.*?)</title>", doc, re.S).group(1))
    dom = dump_dom(out)
    check(f"{name}_dom_dumped", "<body" in dom, dom[:300])
    p = Parsed()
    p.feed(dom)
    check(f"{name}_no_script_ran", "xss-ran" not in p.tags, sorted(p.tags - EXPECTED_TAGS))
    check(f"{name}_title_unchanged", "".join(p.title) == title, ("".join(p.title), title))
    check(f"{name}_dom_tags", p.tags <= EXPECTED_TAGS, sorted(p.tags - EXPECTED_TAGS))

r = daq("model", "map", "hostile-model.json", "--report", "model.html")
check("model_written", r.returncode == 0, r.stdout + r.stderr)
if r.returncode == 0:
    check_html("model", os.path.join(TMP, "model.html"), ["machine"])

# --- (c) the PDF: no local file in it, the name is ------------------------------------------------
def pdf_text(path):
    return subprocess.run(["pdftotext", path, "-"], capture_output=True, text=True).stdout


squash = lambda s: re.sub(r"\s+", "", s)  # noqa: E731  (pdftotext breaks lines in table cells)
for name, what in (("run", ["report", RUN, "--db", "demo.sqlite"]),
                   ("rtx", ["report", "1", "--db", "rtx.sqlite"]),
                   ("ballbar5x", ["report", "1", "--db", "bb5x.sqlite"])):
    pdf = os.path.join(TMP, f"{name}.pdf")
    r = daq(*what, "--format", "pdf", "-o", pdf)
    check(f"{name}_pdf_written", r.returncode == 0 and open(pdf, "rb").read(4) == b"%PDF",
          r.stdout + r.stderr)
    if r.returncode != 0:
        continue
    text = pdf_text(pdf)
    check(f"{name}_pdf_no_local_file", MARKER not in text, "the secret file is in the PDF")
    check(f"{name}_pdf_shows_name", squash(names["machine"]) in squash(text), text[:1500])

# --- how the PDF is printed: a stand-in browser records what it is given and sees ----------------
seen = os.path.join(TMP, "seen")
printer = os.path.join(TMP, "printer.sh")
with open(printer, "w") as f:
    f.write(f"""#!/bin/bash
for a; do printf '%s\\n' "$a"; done >"{seen}.args"
for a; do case $a in --print-to-pdf=*) out=${{a#*=}} ;; file://*) page=${{a#file://}} ;; esac; done
dir=$(dirname "$page")
stat -c %a "$(dirname "$dir")" >"{seen}.mode"
ls -A "$dir" >"{seen}.ls"
echo "$dir" >"{seen}.dir"
echo "HOME=$HOME" >"{seen}.env"
printf '%%PDF-1.4\\n%%%%EOF\\n' >"$out"
""")
os.chmod(printer, 0o755)
hostile_out = "it's $(touch pwned) `touch pwned2`.pdf"
r = daq("report", RUN, "--db", "demo.sqlite", "--format", "pdf", "-o", hostile_out,
        env=dict(os.environ, CALDAQ_CHROMIUM=printer))
check("pdf_quoted_path_written", r.returncode == 0 and
      open(os.path.join(TMP, hostile_out), "rb").read(4) == b"%PDF", r.stdout + r.stderr)
check("pdf_no_shell", not os.path.exists(os.path.join(TMP, "pwned")) and
      not os.path.exists(os.path.join(TMP, "pwned2")), os.listdir(TMP))
read = lambda s: open(f"{seen}.{s}").read() if os.path.exists(f"{seen}.{s}") else ""  # noqa: E731
args = read("args").splitlines()
check("pdf_private_dir_mode", read("mode").strip() == "700", read("mode"))
check("pdf_private_dir_only_report", read("ls").split() == ["report.html"], read("ls"))
# The private directory is the page's directory's parent (the profile and PDF beside it).
private = os.path.dirname(read("dir").strip())
check("pdf_private_dir_removed", private.startswith("/") and not os.path.exists(private), private)
check("pdf_home_private", read("env").strip() == "HOME=" + private, read("env"))
for flag in ("--proxy-server=127.0.0.1:9", "--proxy-bypass-list=<-loopback>",
             "--host-resolver-rules=MAP * ~NOTFOUND"):
    check(f"pdf_flag_{flag.split('=')[0][2:]}", flag in args, args)
check("pdf_fresh_profile", any(a.startswith("--user-data-dir=" + private + "/")
                               for a in args), args)
# A browser that fails: the message names the PDF, the browser and its kept output.
with open(printer, "w") as f:
    f.write("#!/bin/bash\necho 'no display here' >&2\nexit 3\n")
r = daq("report", RUN, "--db", "demo.sqlite", "--format", "pdf", "-o", "fail.pdf",
        env=dict(os.environ, CALDAQ_CHROMIUM=printer))
check("pdf_failure_message", r.returncode == 2 and "did not print the report (exit status 3)"
      in r.stderr and "fail.pdf.log" in r.stderr, r.stderr)
log = os.path.join(TMP, "fail.pdf.log")
check("pdf_failure_log_kept", os.path.exists(log) and "no display here" in open(log).read(),
      "no fail.pdf.log with the browser's output")

print(f"{passes} passed, {len(failures)} failed")
if failures:
    print("kept for a look:", TMP)
else:
    shutil.rmtree(TMP, ignore_errors=True)
sys.exit(1 if failures else 0)
