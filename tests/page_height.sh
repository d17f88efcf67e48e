# Sourced by the report tests (report_html_test.sh, campaign_test.sh), after $tmp is set:
# page_height PAGE prints the height in px of an HTML page laid out 1200 px wide, by headless
# Chromium (a parent page in $tmp with a script reads the page's scroll height: the page itself
# forbids scripts); nothing when chromium cannot tell.
page_height() {
  cat >"$tmp/page_height.html" <<HTML
<!DOCTYPE html><html><body style="margin:0"><iframe id="f" src="file://$1" style="width:1200px;height:600px;border:0"></iframe>
<script>document.getElementById("f").addEventListener("load", function () {
  document.body.setAttribute("data-height", this.contentDocument ? this.contentDocument.documentElement.scrollHeight : -1); });</script>
</body></html>
HTML
  timeout 60 chromium --headless --disable-gpu --no-sandbox --no-first-run --user-data-dir="$tmp/page_height_profile" \
    --allow-file-access-from-files --virtual-time-budget=3000 --dump-dom "file://$tmp/page_height.html" 2>/dev/null |
    sed -n 's/.*data-height="\([0-9-]*\)".*/\1/p'
}
