"""Open a page in headless Chromium and say what a reader would see: console errors, the size each figure is drawn
at, and the page printed to PDF. For the browser tests of the report and the certificate.

Chromium is driven through the DevTools protocol over a pipe (``--remote-debugging-pipe``: commands on file
descriptor 3, answers on 4, JSON separated by NUL bytes), so nothing but Chromium itself is needed (no network,
no driver package). ``chromium()`` finds the browser (Debian's package ``chromium``), or None.
"""

from __future__ import annotations

import base64
import contextlib
import json
import math
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

#: a Letter page's printable height at Chromium's default margins (0.4 in top and bottom) [CSS px]
PRINTABLE_HEIGHT_PX, PRINTABLE_WIDTH_PX = (11.0 - 0.8) * 96, (8.5 - 0.8) * 96
#: the flags the machines here need for a headless Chromium without network (see the env notes)
FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
)
#: each figure's natural and drawn size: an image that did not decode has a natural width of 0
_FIGURES_JS = """JSON.stringify(Array.from(document.querySelectorAll('img, svg, canvas')).map(e => {
  const r = e.getBoundingClientRect();
  return {tag: e.tagName, alt: e.getAttribute('alt') || '', natural: e.naturalWidth === undefined ? -1 : e.naturalWidth,
          width: r.width, height: r.height, complete: e.complete === undefined ? true : e.complete};
}))"""

#: the first screen a reader sees: a laptop's browser window [px]
SCREEN_PX = (1280, 900)
#: each section and table as laid out on that screen: its section's id, caption, top and bottom [px]
_LAYOUT_JS = """JSON.stringify(Array.from(document.querySelectorAll('section, table')).map(e => {
  const r = e.getBoundingClientRect(), s = e.closest('section');
  const caption = e.tagName === 'TABLE' && e.caption ? e.caption.textContent : '';
  return {tag: e.tagName, section: s ? s.id : '', caption: caption, top: r.top + window.scrollY,
          bottom: r.bottom + window.scrollY, text: e.tagName === 'TABLE' ? e.innerText : ''};
}))"""


def chromium() -> str | None:
    return shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")


@dataclass(frozen=True)
class PageSeen:
    """What the browser saw: the console's errors (and uncaught exceptions), each figure as a dict (tag, alt,
    natural width, drawn width and height), and the PDF's bytes and page count."""

    errors: tuple[str, ...]
    figures: tuple[dict, ...]
    pdf: bytes
    pdf_pages: int
    height_px: float
    #: each section and table laid out in a window of SCREEN_PX (section, caption, top, bottom [px], a table's text)
    layout: tuple[dict, ...] = ()

    def on_first_screen(self) -> tuple[dict, ...]:
        """The sections and tables wholly inside the first screen (their bottom above SCREEN_PX's height)."""
        return tuple(e for e in self.layout if e["bottom"] <= SCREEN_PX[1])

    def pages_expected(self) -> tuple[int, int]:
        """The fewest and most pages the page's printed height gives on Letter with Chromium's default margins
        (10.2 in of 96 px printable): at least the whole pages it fills (its last margin may not print), at most
        one more, and one more per figure (a figure that does not fit at a page's end goes to the next)."""
        pages = self.height_px / PRINTABLE_HEIGHT_PX
        return max(1, math.floor(pages)), math.ceil(pages) + len(self.figures)


class _Pipe:
    def __init__(self, process: subprocess.Popen, write_fd: int, read_fd: int):
        self.process, self.write_fd, self.read_fd = process, write_fd, read_fd
        self.buffer, self.next_id, self.events = b"", 0, []

    def send(self, method: str, params: dict | None = None, session: str | None = None) -> dict:
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self.write_fd, json.dumps(message).encode() + b"\0")
        while True:
            reply = self._read()
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_for(self, method: str, timeout_s: float) -> dict:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            for i, event in enumerate(self.events):
                if event.get("method") == method:
                    return self.events.pop(i)
            self.events.append(self._read())
        raise TimeoutError(method)

    def _read(self) -> dict:
        while b"\0" not in self.buffer:
            chunk = os.read(self.read_fd, 1 << 16)
            if not chunk:
                raise RuntimeError("chromium closed its pipe")
            self.buffer += chunk
        text, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(text)


def open_page(path: str | os.PathLike, timeout_s: float = 60.0) -> PageSeen:
    """Load the file ``path`` in headless Chromium, wait for its load event, and return what it saw."""
    browser = chromium()
    if browser is None:
        raise RuntimeError("no chromium (apt-get install chromium)")
    to_chrome_r, to_chrome_w = os.pipe()
    from_chrome_r, from_chrome_w = os.pipe()
    with tempfile.TemporaryDirectory(ignore_cleanup_errors=True) as profile:

        def onto_3_and_4() -> None:  # in the child: the pipe's ends on 3 and 4, where Chromium looks for them
            read_end, write_end = os.dup(to_chrome_r), os.dup(from_chrome_w)  # clear of 3 and 4 first
            os.dup2(read_end, 3)
            os.dup2(write_end, 4)

        process = subprocess.Popen(
            [browser, *FLAGS, f"--user-data-dir={profile}", "--remote-debugging-pipe", "about:blank"],
            close_fds=False,
            preexec_fn=onto_3_and_4,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        pipe = _Pipe(process, to_chrome_w, from_chrome_r)
        try:
            target = pipe.send("Target.createTarget", {"url": "about:blank"})["targetId"]
            session = pipe.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
            for domain in ("Page", "Runtime", "Log"):
                pipe.send(f"{domain}.enable", session=session)
            pipe.send("Page.navigate", {"url": Path(path).resolve().as_uri()}, session=session)
            pipe.wait_for("Page.loadEventFired", timeout_s)
            seen = pipe.send("Runtime.evaluate", {"expression": _FIGURES_JS, "returnByValue": True}, session=session)
            figures = tuple(json.loads(seen["result"]["value"]))
            pipe.send(
                "Emulation.setDeviceMetricsOverride",
                {"width": SCREEN_PX[0], "height": SCREEN_PX[1], "deviceScaleFactor": 1, "mobile": False},
                session=session,
            )
            laid = pipe.send("Runtime.evaluate", {"expression": _LAYOUT_JS, "returnByValue": True}, session=session)
            layout = tuple(json.loads(laid["result"]["value"]))
            # the height as printed: print media at the printable width of a Letter page (0.4 in margins)
            pipe.send("Emulation.setEmulatedMedia", {"media": "print"}, session=session)
            pipe.send(
                "Emulation.setDeviceMetricsOverride",
                {"width": int(PRINTABLE_WIDTH_PX), "height": 1000, "deviceScaleFactor": 1, "mobile": False},
                session=session,
            )
            height = pipe.send(
                "Runtime.evaluate",
                {"expression": "document.documentElement.scrollHeight", "returnByValue": True},
                session=session,
            )["result"]["value"]
            pipe.send("Emulation.clearDeviceMetricsOverride", session=session)
            printed = pipe.send("Page.printToPDF", {"printBackground": True}, session=session)
            pdf = base64.b64decode(printed["data"])
            errors = tuple(_errors(pipe.events))
        finally:  # the browser and its helper processes, all of its session
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGKILL)
            process.wait()
            os.close(to_chrome_w)
            os.close(from_chrome_r)
    return PageSeen(errors, figures, pdf, pdf_page_count(pdf), float(height), layout)


def _errors(events: list[dict]) -> list[str]:
    out = []
    for event in events:
        method, params = event.get("method"), event.get("params", {})
        if method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
            out.append(" ".join(str(a.get("value", a.get("description", ""))) for a in params.get("args", [])))
        elif method == "Runtime.exceptionThrown":
            out.append(params.get("exceptionDetails", {}).get("text", "exception"))
        elif method == "Log.entryAdded" and params.get("entry", {}).get("level") == "error":
            out.append(params["entry"].get("text", ""))
    return out


def pdf_page_count(pdf: bytes) -> int:
    """The pages of a PDF: its page objects (``/Type /Page``, not ``/Pages``)."""
    return len(re.findall(rb"/Type\s*/Page(?![a-zA-Z])", pdf))
