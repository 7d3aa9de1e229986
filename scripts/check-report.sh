#!/usr/bin/env bash
# Open a `study report` page in a real headless browser, 1280 px wide, and
# check that it renders: no script error and no console error, every figure
# has a non-empty box, the ranking table has rows, nothing is wider than its
# box (the page, a paragraph, a figure; the table may scroll inside its
# own), and nothing is fetched from elsewhere. Then it takes a screenshot of
# the whole page, as tall as the page is (so the last figure and the
# provenance are on it), into SCREENSHOT.png if given.
# Usage: scripts/check-report.sh REPORT.html [SCREENSHOT.png]
# First, everywhere, the HTML's own rules: every table inside a scrolling
# box, figures and images at most the column's width, no Markdown backtick
# in a caption or cell (also `cargo test --test it report`).
# Exit 0: checked (with no browser here the browser part is said plainly to
# be skipped); 1: a check failed; 2: usage.
# Needs python3, and Chromium for the browser part (Debian: apt-get install
# chromium).
set -euo pipefail
report=${1:?usage: scripts/check-report.sh REPORT.html [SCREENSHOT.png]}
screenshot=${2:-}
width=1280
[ -f "$report" ] || { echo "check-report: $report: no such file" >&2; exit 2; }

# Without a browser too: the HTML itself keeps everything inside its box
# (the rules of `cargo test --test it report`, here on any report).
python3 - "$report" <<'EOF'
import re, sys
page = open(sys.argv[1], encoding="utf-8").read()
style = (re.search(r"<style>(.*?)</style>", page, re.S) or [None, ""])[1]
rules = {sel.strip(): body.replace(" ", "") for sels, body in re.findall(r"([^{}]+)\{([^}]*)\}", style) for sel in sels.split(",")}
problems = [f"no rule `{sel} {{ {need} }}`" for sel, need in
            [(".scroll", "overflow-x:auto"), ("figure svg", "max-width:100%"), ("img", "max-width:100%"), ("pre", "overflow-x:auto")]
            if need not in rules.get(sel, "")]
problems += ["a table outside a scrolling box" for m in re.finditer(r"<table", page) if not page[:m.start()].endswith('<div class="scroll">')]
problems += [f"a literal backtick in <{tag}>: {text[:60]}" for tag in ("figcaption", "p", "td", "th", "dd")
             for text in re.findall(rf"<{tag}(?:\s[^>]*)?>(.*?)</{tag}>", page, re.S) if "`" in text]
if problems:
    print(f"check-report: {sys.argv[1]}: " + "; ".join(problems), file=sys.stderr)
    sys.exit(1)
print(f"check-report: {sys.argv[1]}: the HTML keeps tables, figures and code inside their boxes")
EOF

browser=""
for b in chromium chromium-browser google-chrome google-chrome-stable; do
    if command -v "$b" >/dev/null 2>&1; then browser=$(command -v "$b"); break; fi
done
if [ -z "$browser" ]; then
    echo "check-report: no Chromium here, so the report was NOT checked in a browser (install one: apt-get install chromium)"
    exit 0
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/check-report.XXXXXX")
trap 'rm -rf "$work"' EXIT

# A copy of the page with a probe: errors are caught from the first line
# on, and after load each figure's box and the table are measured into the
# DOM, which the browser prints.
python3 - "$report" "$work/page.html" <<'EOF'
import re, sys
src, dst = sys.argv[1], sys.argv[2]
html = open(src, encoding="utf-8").read()
# Nothing may be fetched: no src/href/url() to another place.
external = re.findall(r'''(?:src|href)\s*=\s*["'](?!#|data:)[^"']+|url\(\s*["']?(?!#|data:)[^)'"]+''', html)
if external:
    print("check-report: the page fetches from elsewhere:", external[:5], file=sys.stderr)
    sys.exit(1)
catch = """<script>window.__errors=[];window.addEventListener('error',function(e){__errors.push(String(e.message))});
var __ce=console.error;console.error=function(){__errors.push(Array.prototype.join.call(arguments,' '));__ce.apply(console,arguments)};</script>"""
probe = """<script>window.addEventListener('load',function(){
var figs=[].slice.call(document.querySelectorAll('figure'));
var boxes=figs.map(function(f){var s=f.querySelector('svg');if(!s)return [f.id,0,0];var r=s.getBoundingClientRect();return [f.id,r.width,r.height]});
var rows=document.querySelectorAll('#ranking-table tbody tr').length;
var root=document.documentElement, overflow=[];
if(root.scrollWidth>root.clientWidth+1)overflow.push('the page is '+root.scrollWidth+' px wide in a '+root.clientWidth+' px window');
var main=document.querySelector('main'), right=main.getBoundingClientRect().right+1;
[].slice.call(main.querySelectorAll('section, p, figure, figcaption, svg, dl, dd, div, pre, table, h1, h2')).forEach(function(el){
  if(el.closest('.scroll, pre')&&!el.matches('.scroll, pre'))return;
  var r=el.getBoundingClientRect(), what=el.tagName.toLowerCase()+(el.id?'#'+el.id:'')+(el.className&&typeof el.className==='string'?'.'+el.className:'');
  if(r.right>right)overflow.push(what+' reaches '+Math.round(r.right)+' px, past the column at '+Math.round(right));
  var ox=getComputedStyle(el).overflowX;
  if(ox==='visible'&&el.scrollWidth>el.clientWidth+1&&el.clientWidth>0)overflow.push(what+' holds '+el.scrollWidth+' px in '+el.clientWidth);
});
var out=document.createElement('pre');out.id='__check';
out.textContent=JSON.stringify({errors:window.__errors,boxes:boxes,rows:rows,overflow:overflow,height:Math.ceil(root.scrollHeight)});document.body.appendChild(out)});</script>"""
html = html.replace("<head>", "<head>" + catch, 1).replace("</body>", probe + "</body>", 1)
open(dst, "w", encoding="utf-8").write(html)
EOF

"$browser" --headless --no-sandbox --disable-gpu --window-size=$width,3000 \
    --virtual-time-budget=10000 --enable-logging=stderr --v=0 \
    --dump-dom "file://$work/page.html" >"$work/dom.html" 2>"$work/browser.log" || true

python3 - "$work/dom.html" "$work/browser.log" "$report" "$work/height" <<'EOF'
import html as h, json, re, sys
dom, log = (open(p, encoding="utf-8", errors="replace").read() for p in sys.argv[1:3])
report = sys.argv[3]
m = re.search(r'<pre id="__check">(.*?)</pre>', dom, re.S)
if not m:
    print("check-report: the page did not finish loading in the browser", file=sys.stderr)
    print(log[-2000:], file=sys.stderr)
    sys.exit(1)
result = json.loads(h.unescape(m.group(1)))
problems = []
problems += ["script error: " + e for e in result["errors"]]
problems += ["console: " + l for l in log.splitlines() if "Uncaught" in l or ("CONSOLE" in l and "error" in l.lower())]
if not result["boxes"]:
    problems.append("no figure")
problems += [f"figure {i} has an empty box ({w:.0f} x {hgt:.0f})" for i, w, hgt in result["boxes"] if w < 10 or hgt < 10]
if result["rows"] < 1:
    problems.append("the ranking table has no row")
problems += ["overflow: " + o for o in result["overflow"]]
open(sys.argv[4], "w").write(str(result["height"]))
if problems:
    print(f"check-report: {report}: " + "; ".join(problems), file=sys.stderr)
    sys.exit(1)
print(f"check-report: {report}: rendered in Chromium at 1280 px: {len(result['boxes'])} figures with non-empty boxes, "
      f"ranking table with {result['rows']} rows, nothing wider than its box, no script or console error, nothing fetched")
EOF

# The screenshot is as tall as the page (a fixed window height cut off the
# last figure and the provenance).
height=$(cat "$work/height")
shot=${screenshot:-$work/page.png}
"$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
    --window-size=$width,"$height" --virtual-time-budget=10000 \
    --screenshot="$shot" "file://$work/page.html" >/dev/null 2>>"$work/browser.log" || true
python3 - "$shot" "$height" <<'EOF'
import struct, sys
shot, height = sys.argv[1], int(sys.argv[2])
try:
    head = open(shot, "rb").read(24)
except OSError:
    print(f"check-report: no screenshot was taken ({shot})", file=sys.stderr)
    sys.exit(1)
w, h = struct.unpack(">II", head[16:24])
if h < height:
    print(f"check-report: the screenshot is {h} px tall, the page {height} px", file=sys.stderr)
    sys.exit(1)
print(f"check-report: screenshot of the whole page, {w} x {h} px: {shot}")
EOF
