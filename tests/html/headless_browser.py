"""Render local HTML pages in headless Chromium, driven over the DevTools protocol.

Launching chromium costs ~2.5 s, so starting one browser per page makes a CI run
over many pages far too slow.  Instead ONE browser process is started with
``--remote-debugging-pipe`` and every page is navigated in the same tab.  The
pipe (chromium reads commands on fd 3 and writes responses/events on fd 4, each
message a JSON object ended by a NUL byte) needs no free TCP port and no
websocket client (standard library only), and reports EOF the moment chromium
dies, so a crash raises an error instead of hanging.

    with HeadlessBrowser() as browser:
        page = browser.load("tests/html/page.html")
        assert not page.console_errors and not png_is_blank(page.screenshot_png)

The PNG helpers decode screenshots with zlib only, so tests can check that a
page rendered something.  ``python3 headless_browser.py PAGE.html
[--screenshot OUT.png]`` inspects a single page by hand.
"""

import base64, contextlib, dataclasses, fcntl, itertools, json, math, os, pathlib
import select, shutil, signal, struct, subprocess, sys, tempfile, time, zlib


class BrowserError(RuntimeError):
    """Chromium failed, timed out, exited, or answered a command with an error."""


@dataclasses.dataclass
class PageResult:
    url: str
    screenshot_png: bytes      # full-page screenshot
    dom: str                   # document.documentElement.outerHTML after load
    console_errors: list[str]  # console.error/assert, uncaught exceptions, Log errors
    requests: list[str]        # URL of every request the page made, document included
    title: str


class HeadlessBrowser:
    """One headless chromium process; ``load()`` renders pages one after another."""

    FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--remote-debugging-pipe",
             "--no-first-run", "--no-default-browser-check", "--disable-extensions",
             "--disable-background-networking", "--disable-dev-shm-usage",
             "--hide-scrollbars", "--mute-audio"]

    def __init__(self, chromium="chromium", width=1280, height=900, timeout=30.0):
        self.timeout, self._size = timeout, (width, height)
        self._proc = self._session = self._target = self._rfd = self._wfd = None
        self._next_id, self._buf = 0, bytearray()
        self._reset_page()
        self._tmpdir = tempfile.mkdtemp(prefix="headless_browser_")
        self._stderr = open(os.path.join(self._tmpdir, "stderr.log"), "w+b")
        try:
            self._spawn(chromium)
            self._open_tab()
        except BaseException:
            self.close()
            raise

    def _spawn(self, chromium):
        # Pipe A: parent -> chromium's fd 3.  Pipe B: chromium's fd 4 -> parent.
        a_r, self._wfd = os.pipe()
        self._rfd, b_w = os.pipe()
        # Park the child ends at fds >= 10 so that dup2 onto 3/4 never aliases
        # them (dup2(fd, fd) would keep FD_CLOEXEC and lose the fd at exec).
        child_r = fcntl.fcntl(a_r, fcntl.F_DUPFD_CLOEXEC, 10)
        child_w = fcntl.fcntl(b_w, fcntl.F_DUPFD_CLOEXEC, 10)
        os.close(a_r)
        os.close(b_w)

        def in_child():        # dup2 clears FD_CLOEXEC, so 3 and 4 survive exec
            os.dup2(child_r, 3)
            os.dup2(child_w, 4)

        args = [chromium, *self.FLAGS, "--window-size=%d,%d" % self._size,
                "--user-data-dir=" + os.path.join(self._tmpdir, "profile"), "about:blank"]
        try:   # Python's own fds are non-inheritable: close_fds=False passes only 0-4
            self._proc = subprocess.Popen(
                args, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                stderr=self._stderr, close_fds=False, preexec_fn=in_child,
                start_new_session=True)   # own process group, killed as a whole
        finally:
            os.close(child_r)   # now only chromium holds these: EOF means it died
            os.close(child_w)

    def _open_tab(self):
        """Attach to a fresh tab, closing the previous one (its renderer may hang)."""
        old, self._session = self._target, None   # browser-level commands from here
        if old:
            with contextlib.suppress(BrowserError):
                self._send("Target.closeTarget", {"targetId": old})
        self._target = self._send("Target.createTarget", {"url": "about:blank"})["targetId"]
        self._session = self._send("Target.attachToTarget", {
            "targetId": self._target, "flatten": True})["sessionId"]
        for domain in ("Page", "Runtime", "Log", "Network"):
            self._send(domain + ".enable")
        self._send("Network.setCacheDisabled", {"cacheDisabled": True})
        self._send("Emulation.setDeviceMetricsOverride", {
            "width": self._size[0], "height": self._size[1], "deviceScaleFactor": 1,
            "mobile": False})
        self._tab_ok = True

    # --- protocol ----------------------------------------------------------

    def _fail(self, what):
        try:   # after EOF the process may need a moment to become reapable
            code = self._proc.wait(timeout=0.2) if self._proc else None
        except subprocess.TimeoutExpired:
            code = None
        state = "chromium still running" if code is None else f"chromium exited ({code})"
        self._stderr.seek(0)
        tail = self._stderr.read()[-2000:].decode("utf-8", "replace")
        raise BrowserError(f"{what} ({state}); chromium stderr tail:\n{tail}")

    def _wait_fd(self, fd, write, deadline, what):
        rlist, wlist = ([], [fd]) if write else ([fd], [])
        if not any(select.select(rlist, wlist, [], max(0.0, deadline - time.monotonic()))):
            self._fail(f"timed out after {self.timeout}s waiting for {what}")

    def _send(self, method, params=None):
        """Send a command (to the page session once attached) and return its result."""
        if self._proc is None:
            raise BrowserError("browser is closed")
        self._next_id += 1
        msg = {"id": self._next_id, "method": method, "params": params or {}}
        if self._session:
            msg["sessionId"] = self._session
        data = json.dumps(msg).encode() + b"\0"
        deadline = time.monotonic() + self.timeout
        try:
            while data:
                self._wait_fd(self._wfd, True, deadline, f"sending {method}")
                data = data[os.write(self._wfd, data):]
        except BrokenPipeError:
            self._fail(f"pipe closed while sending {method}")
        while True:   # events arriving meanwhile are handled by _read_message
            reply = self._read_message(deadline, f"the reply to {method}")
            if reply.get("id") == msg["id"]:
                if "error" in reply:
                    raise BrowserError(f"{method} failed: {reply['error']}")
                return reply.get("result", {})

    def _read_message(self, deadline, what):
        """Return the next message; events of our session also go to _on_event."""
        scan = 0
        while (end := self._buf.find(b"\0", scan)) < 0:
            scan = len(self._buf)
            self._wait_fd(self._rfd, False, deadline, what)
            chunk = os.read(self._rfd, 1 << 20)
            if not chunk:
                self._fail(f"chromium closed the pipe while we waited for {what}")
            self._buf += chunk
        msg = json.loads(self._buf[:end])
        del self._buf[:end + 1]
        if "method" in msg and self._session and msg.get("sessionId") == self._session:
            self._on_event(msg["method"], msg.get("params", {}))
        return msg

    def _reset_page(self):
        self._loaded = self._crashed = False
        self._errors, self._requests = [], []

    def _on_event(self, method, p):
        if method == "Page.loadEventFired":
            self._loaded = True
        elif method == "Inspector.targetCrashed":
            self._crashed = True
        elif method == "Network.requestWillBeSent":
            self._requests.append(p["request"]["url"])
        elif method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            text = " ".join(_remote_object_text(a) for a in p.get("args", []))
            self._errors.append(("console.assert: " if p["type"] == "assert" else "") + text)
        elif method == "Runtime.exceptionThrown":
            d = p.get("exceptionDetails", {})
            desc = d.get("exception", {}).get("description") or d.get("text", "")
            self._errors.append(f"uncaught exception: {desc}")
        elif method == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
            e = p["entry"]
            url = f" ({e['url']})" if e.get("url") else ""
            self._errors.append(f"{e.get('source', 'log')}: {e.get('text', '')}{url}")

    def _evaluate(self, expression, await_promise=False):
        r = self._send("Runtime.evaluate", {"expression": expression, "returnByValue": True,
                                            "awaitPromise": await_promise})
        if "exceptionDetails" in r:
            raise BrowserError(f"evaluating {expression!r} threw: {r['exceptionDetails']}")
        return r["result"].get("value")

    # --- public API --------------------------------------------------------

    def load(self, path_or_url, max_height=None, scale=1.0):
        """Navigate to a file path or URL, wait for load + a frame, collect results.

        The screenshot is of the whole page, or of its top ``max_height`` CSS
        pixels when given (a long page's full screenshot costs seconds), at
        ``scale`` device pixels per CSS pixel."""
        url = str(path_or_url)
        if "://" not in url and not url.startswith(("about:", "data:")):
            url = pathlib.Path(url).resolve().as_uri()
        if not self._tab_ok:   # the previous load() failed: start from a fresh tab
            self._open_tab()
        self._tab_ok = False
        self._reset_page()
        nav = self._send("Page.navigate", {"url": url})
        if nav.get("errorText"):
            raise BrowserError(f"navigating to {url} failed: {nav['errorText']}")
        deadline = time.monotonic() + self.timeout
        while nav.get("loaderId") and not self._loaded:   # no loaderId: same-document
            if self._crashed:
                self._fail(f"the renderer crashed loading {url}")
            self._read_message(deadline, f"the load event of {url}")
        self._evaluate("new Promise(r => requestAnimationFrame(() => "
                       "requestAnimationFrame(r)))", await_promise=True)
        dom = self._evaluate("document.documentElement?.outerHTML ?? ''")
        title = self._evaluate("document.title")
        metrics = self._send("Page.getLayoutMetrics")
        size = metrics.get("cssContentSize") or metrics["contentSize"]
        clip = {"x": 0, "y": 0, "scale": scale, "width": max(1, math.ceil(size["width"])),
                "height": max(1, math.ceil(size["height"]))}
        if max_height:
            clip["height"] = min(clip["height"], max_height)
        # optimizeForSpeed makes chromium use only the "Up" filter: fast to decode here
        shot = self._send("Page.captureScreenshot", {
            "format": "png", "captureBeyondViewport": True, "clip": clip,
            "optimizeForSpeed": True})
        self._tab_ok = True
        return PageResult(url=url, screenshot_png=base64.b64decode(shot["data"]), dom=dom,
                          console_errors=list(self._errors), requests=list(self._requests),
                          title=title)

    def close(self):
        """Kill chromium's whole process group, reap it, delete the profile.

        (A graceful Browser.close takes ~0.7 s more and still leaves chromium's
        zygote helpers to be reaped by init, just like the SIGKILL does.)"""
        proc, self._proc = self._proc, None
        if proc is not None:
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                proc.kill()
            proc.wait()
        for name in ("_wfd", "_rfd"):
            if getattr(self, name, None) is not None:
                os.close(getattr(self, name))
                setattr(self, name, None)
        if getattr(self, "_stderr", None):
            self._stderr.close()
        if getattr(self, "_tmpdir", None):
            shutil.rmtree(self._tmpdir, ignore_errors=True)
            self._tmpdir = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        if getattr(self, "_proc", None) is not None:
            self.close()


def _remote_object_text(obj):
    if "value" in obj:
        return obj["value"] if isinstance(obj["value"], str) else json.dumps(obj["value"])
    return str(obj.get("unserializableValue") or obj.get("description") or obj.get("type"))


# --- PNG decoding (zlib only) ------------------------------------------------

def _png_chunks(png):
    if png[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos = 8
    while pos + 8 <= len(png):
        length, kind = struct.unpack(">I4s", png[pos:pos + 8])
        yield kind, png[pos + 8:pos + 8 + length]
        pos += 12 + length


def png_size(png):
    """(width, height) from the IHDR chunk."""
    return struct.unpack(">II", next(_png_chunks(png))[1][:8])


def _png_rgbx(png):
    """Decode to (width, height, pixels) with 4 bytes per pixel: R, G, B, 0."""
    chunks = list(_png_chunks(png))
    w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", chunks[0][1])
    chans = {0: 1, 2: 3, 4: 2, 6: 4}.get(ctype)   # gray, RGB, gray+alpha, RGBA
    if chans is None or depth not in (8, 16) or interlace:
        raise ValueError(f"unsupported PNG: colour type {ctype}, bit depth {depth}, "
                         f"interlace {interlace}")
    data = zlib.decompress(b"".join(d for kind, d in chunks if kind == b"IDAT"))
    px = _unfilter(data, w, h, chans * depth // 8)
    if depth == 16:
        px = px[0::2]   # keep the high byte of each sample
    out = bytearray(w * h * 4)
    for k, src in enumerate((0, 1, 2) if chans >= 3 else (0, 0, 0)):
        out[k::4] = px[src::chans]
    return w, h, out


def _unfilter(data, width, height, bpp):
    """Undo the per-scanline filters 0-4 (None, Sub, Up, Average, Paeth)."""
    stride = width * bpp
    out, prev = bytearray(stride * height), bytes(stride)
    mask = (255).__and__
    # SWAR masks: add two whole rows as big integers without carries between bytes
    low7 = int.from_bytes(b"\x7f" * stride, "big")
    high1 = int.from_bytes(b"\x80" * stride, "big")
    for y in range(height):
        start = y * (stride + 1)
        ftype, row = data[start], data[start + 1:start + 1 + stride]
        if ftype == 1:     # Sub: running sum per channel
            row = bytearray(stride)
            for c in range(bpp):
                raw = data[start + 1 + c:start + 1 + stride:bpp]
                row[c::bpp] = bytes(map(mask, itertools.accumulate(raw)))
        elif ftype == 2:   # Up: bytewise (row + prev) mod 256
            x, p = int.from_bytes(row, "big"), int.from_bytes(prev, "big")
            row = (((x & low7) + (p & low7)) ^ ((x ^ p) & high1)).to_bytes(stride, "big")
        elif ftype in (3, 4):   # Average, Paeth: inherently sequential
            row = bytearray(row)
            for i in range(stride):
                a, b = (row[i - bpp] if i >= bpp else 0), prev[i]
                if ftype == 3:
                    pred = (a + b) >> 1
                else:
                    c = prev[i - bpp] if i >= bpp else 0
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                row[i] = (row[i] + pred) & 255
        elif ftype != 0:
            raise ValueError(f"bad PNG filter type {ftype} in row {y}")
        out[y * stride:(y + 1) * stride] = prev = row
    return out


def png_is_blank(png):
    """True if every pixel has the same RGB colour (alpha ignored)."""
    w, h, px = _png_rgbx(png)
    return px == px[:4] * (w * h)


def png_distinct_colours(png, limit=100000):
    """Number of distinct RGB colours in the image, capped at ``limit``."""
    return min(limit, len(set(memoryview(_png_rgbx(png)[2]).cast("I"))))


def main(argv=None):
    import argparse
    ap = argparse.ArgumentParser(description="Render one HTML page in headless chromium.")
    ap.add_argument("page")
    ap.add_argument("--screenshot", metavar="OUT.png", help="write the screenshot here")
    ap.add_argument("--chromium", default="chromium")
    args = ap.parse_args(argv)
    t0 = time.monotonic()
    with HeadlessBrowser(args.chromium) as browser:
        r = browser.load(args.page)
    png, blank = r.screenshot_png, " (blank)" if png_is_blank(r.screenshot_png) else ""
    print(f"url:            {r.url}\ntitle:          {r.title!r}\nscreenshot:     "
          "%dx%d, %d colours%s" % (*png_size(png), png_distinct_colours(png), blank))
    for label, items in (("console errors", r.console_errors), ("requests", r.requests)):
        print(f"{label + ':':16}{len(items)}" + "".join(f"\n  {x}" for x in items))
    print(f"DOM length:     {len(r.dom)}\nelapsed:        {time.monotonic() - t0:.2f}s")
    if args.screenshot:
        pathlib.Path(args.screenshot).write_bytes(png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
