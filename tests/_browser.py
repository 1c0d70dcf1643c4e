"""Headless Chromium driven through the DevTools protocol on a pipe (``--remote-debugging-pipe``:
JSON messages ended by a NUL byte, the browser reading fd 3 and writing fd 4), standard library
only.

:func:`wait_for_text` opens a page and polls an element until the page has written it: the
test waits for what it measures, however slow the machine, instead of reading the page after
a fixed budget of (virtual) time. The timeout only ends a page that never writes it.
"""

from __future__ import annotations

import json
import os
import subprocess
import time


class DevTools:
    """A Chromium process and its DevTools pipe (a context manager)."""

    def __init__(self, browser: str, flags, profile):
        to_browser_r, self._write = os.pipe()
        self._read, from_browser_w = os.pipe()

        def fds():  # in the child: the pipe's ends as fds 3 and 4, inherited through exec
            import fcntl
            high = [fcntl.fcntl(fd, fcntl.F_DUPFD, 10) for fd in (to_browser_r, from_browser_w)]
            os.dup2(high[0], 3)  # dup2 clears close-on-exec on 3 and 4
            os.dup2(high[1], 4)

        self.proc = subprocess.Popen([browser, *flags, f"--user-data-dir={profile}",
                                      "--remote-debugging-pipe", "about:blank"],
                                     stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.PIPE, preexec_fn=fds, close_fds=False)
        os.close(to_browser_r)
        os.close(from_browser_w)
        self._buffer = b""
        self._id = 0

    def _message(self, deadline: float) -> dict:
        import select
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._read], [], [], left)[0]:
                raise TimeoutError("no answer from chromium")
            chunk = os.read(self._read, 1 << 16)
            if not chunk:
                raise RuntimeError(f"chromium closed its pipe: {self.stderr()}")
            self._buffer += chunk
        text, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(text)

    def call(self, method: str, params=None, session: str | None = None, timeout: float = 60.0):
        """Send a command; return its result (events in between are dropped)."""
        self._id += 1
        message = {"id": self._id, "method": method, "params": params or {}}
        if session is not None:
            message["sessionId"] = session
        os.write(self._write, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            answer = self._message(deadline)
            if answer.get("id") == self._id:
                if "error" in answer:
                    raise RuntimeError(f"{method}: {answer['error']}")
                return answer.get("result", {})

    def stderr(self) -> str:
        return (self.proc.stderr.read() or b"").decode(errors="replace")[-500:] if (
            self.proc.poll() is not None) else ""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        try:
            if self.proc.poll() is None:
                self.call("Browser.close", timeout=10)
        except (OSError, RuntimeError, TimeoutError):
            pass
        finally:
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
            os.close(self._write)
            os.close(self._read)
            self.proc.stderr.close()


def wait_for_text(browser: str, flags, profile, url: str, element_id: str,
                  timeout: float = 300.0, poll: float = 0.1) -> str:
    """Open ``url`` in headless Chromium and return the text of the element ``element_id``
    once the page has written it (polled every ``poll`` seconds)."""
    expression = (f"(function () {{ var e = document.getElementById({json.dumps(element_id)});"
                  " return e ? e.textContent : null; })()")
    with DevTools(browser, flags, profile) as tools:
        target = tools.call("Target.createTarget", {"url": url})["targetId"]
        session = tools.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        deadline = time.monotonic() + timeout
        while True:
            answer = tools.call("Runtime.evaluate", {"expression": expression, "returnByValue": True},
                                session=session)
            if "exceptionDetails" in answer:
                raise RuntimeError(f"{url}: {answer['result'].get('description', answer)}")
            value = answer["result"].get("value")
            if value is not None:
                return value
            if time.monotonic() > deadline:
                raise TimeoutError(f"{url}: no #{element_id} after {timeout} s")
            time.sleep(poll)
