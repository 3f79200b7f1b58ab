#!/usr/bin/python3
"""Screenshots of a recorded irdm-fw run in the view's page (irdm view).

    view-shots.py IRDM LOG BOARD IMAGE OUT.png T1 [T2 ...]

Serves LOG with `irdm view` on a free loopback port, opens the page in
headless Chromium (driven over --remote-debugging-pipe), waits for the
whole recording, and for each time Ti seeks there and takes a screenshot;
the shots are put side by side into OUT.png (matplotlib), each titled with
its time.  Standard library and matplotlib only.
"""
import base64
import fcntl
import io
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

W, H = 1000, 600


class Browser:
    """Chromium over the DevTools pipe: NUL-terminated JSON on fds 3 and 4."""

    def __init__(self, url, profile):
        cmd_r, self.cmd_w = os.pipe()
        self.rep_r, rep_w = os.pipe()
        # out of the way of 3 and 4, where the browser expects them
        hi_r = fcntl.fcntl(cmd_r, fcntl.F_DUPFD_CLOEXEC, 100)
        hi_w = fcntl.fcntl(rep_w, fcntl.F_DUPFD_CLOEXEC, 100)

        def fds():
            os.dup2(hi_r, 3)
            os.dup2(hi_w, 4)

        exe = os.environ.get('IRDM_CHROMIUM', '/usr/bin/chromium')
        self.proc = subprocess.Popen(
            [exe, '--headless', '--no-sandbox', '--remote-debugging-pipe',
             '--force-device-scale-factor=1', '--hide-scrollbars', '--no-first-run',
             f'--window-size={W},{H}', f'--user-data-dir={profile}', 'about:blank'],
            preexec_fn=fds, close_fds=False, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL)
        for fd in (cmd_r, rep_w, hi_r, hi_w):
            os.close(fd)
        self.buf = b''
        self.next_id = 0
        self.session = None
        target = self.call('Target.createTarget', {'url': url})['targetId']
        self.session = self.call('Target.attachToTarget',
                                 {'targetId': target, 'flatten': True})['sessionId']

    def call(self, method, params):
        self.next_id += 1
        msg = {'id': self.next_id, 'method': method, 'params': params}
        if self.session:
            msg['sessionId'] = self.session
        os.write(self.cmd_w, json.dumps(msg).encode() + b'\0')
        while True:
            while b'\0' not in self.buf:
                chunk = os.read(self.rep_r, 1 << 20)
                if not chunk:
                    sys.exit('view-shots: chromium closed its pipe')
                self.buf += chunk
            raw, self.buf = self.buf.split(b'\0', 1)
            reply = json.loads(raw)
            if reply.get('id') == self.next_id:
                if 'error' in reply:
                    sys.exit(f'view-shots: {method}: {reply["error"]}')
                return reply['result']

    def eval(self, expr):
        r = self.call('Runtime.evaluate', {'expression': expr, 'returnByValue': True})
        return r['result'].get('value')

    def shot(self):
        return base64.b64decode(self.call('Page.captureScreenshot', {'format': 'png'})['data'])

    def close(self):
        try:
            self.session = None
            self.call('Browser.close', {})
        except SystemExit:
            pass
        self.proc.wait(timeout=30)


def main():
    if len(sys.argv) < 7:
        sys.exit(__doc__)
    irdm, log, board, image, out = sys.argv[1:6]
    times = [float(t) for t in sys.argv[6:]]
    server = subprocess.Popen([irdm, 'view', log, '--board', board, '--image', image,
                               '--listen', '0'], stdout=subprocess.PIPE, text=True)
    url = None
    for line in server.stdout:
        m = re.match(r'view: (http://\S+/)', line)
        if m:
            url = m.group(1)
            break
    if not url:
        sys.exit('view-shots: irdm view did not serve (see its message above)')
    profile = tempfile.mkdtemp(prefix='irdm-view-shots-')
    shots = []
    try:
        b = Browser(url, profile)
        t0 = time.time()
        while b.eval("window.irdmStats ? (irdmStats.loaded ? 'yes' : 'no') : 'no'") != 'yes':
            if time.time() - t0 > 60:
                sys.exit('view-shots: the page did not load the recording in 60 s')
            time.sleep(0.1)
        for t in times:
            b.eval(f'irdmSeek({t}), "ok"')
            time.sleep(0.5)         # a few animation frames: the chart and the scene drawn
            shots.append((t, b.shot()))
        b.close()
    finally:
        server.terminate()
        server.wait()
        shutil.rmtree(profile, ignore_errors=True)
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(shots), figsize=(6.4 * len(shots), 4.2), dpi=100)
    for ax, (t, png) in zip(axes if len(shots) > 1 else [axes], shots):
        ax.imshow(mpimg.imread(io.BytesIO(png), format='png'))
        ax.set_title(f't = {t:g} s')
        ax.axis('off')
    fig.tight_layout()
    fig.savefig(out)
    print(f'view-shots: {out} ({len(shots)} moments)')


if __name__ == '__main__':
    main()
