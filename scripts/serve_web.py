#!/usr/bin/env python3
"""A small static file server for the web client that answers HTTP range requests.

python3's http.server sends whole files only; the web client reads a PVS file by byte range
(the header, the index, then one block per cell it enters), so this server answers
`Range: bytes=A-B` (one range per request) with 206 Partial Content. Every request is logged as
one JSON line {"path", "status", "range": [A, B] or null, "bytes"} to --log (default stderr):
what the client fetched, byte for byte. Standard library only (Debian's python3).

Usage: serve_web.py DIR [--port N] [--bind ADDR] [--log FILE] [--port-file FILE]
Port 0 picks a free port; --port-file receives the port once the server listens.
"""
import argparse
import http.server
import json
import os
import re
import sys
import threading

RANGE = re.compile(r"^bytes=(\d*)-(\d*)$")
TYPES = {".html": "text/html; charset=utf-8", ".js": "text/javascript; charset=utf-8",
         ".mjs": "text/javascript; charset=utf-8", ".wasm": "application/wasm",
         ".json": "application/json", ".glb": "model/gltf-binary", ".png": "image/png",
         ".css": "text/css; charset=utf-8"}


class Handler(http.server.SimpleHTTPRequestHandler):
    log_lock = threading.Lock()
    log_file = sys.stderr

    def log_message(self, *args):  # the JSON log replaces the default access log
        pass

    def record(self, status, rng, nbytes):
        line = json.dumps({"path": self.path.split("?")[0], "status": status, "range": rng,
                           "bytes": nbytes})
        with self.log_lock:
            self.log_file.write(line + "\n")
            self.log_file.flush()

    def guess_type(self, path):
        return TYPES.get(os.path.splitext(path)[1].lower(), "application/octet-stream")

    def end_headers(self):
        # No caching: every fetch of the client reaches this server and its log.
        self.send_header("Cache-Control", "no-store")
        self.send_header("Accept-Ranges", "bytes")
        super().end_headers()

    def do_HEAD(self):
        self.serve(head=True)

    def do_GET(self):
        self.serve(head=False)

    def serve(self, head):
        path = self.translate_path(self.path)
        if os.path.isdir(path):
            path = os.path.join(path, "index.html")
        try:
            f = open(path, "rb")
        except OSError:
            self.send_error(404, "not found")
            self.record(404, None, 0)
            return
        with f:
            size = os.fstat(f.fileno()).st_size
            header = self.headers.get("Range")
            if header is None:
                start, end, status = 0, size - 1, 200
            else:
                m = RANGE.match(header.strip())
                if not m or (m.group(1) == "" and m.group(2) == ""):
                    self.send_error(416, "only one byte range per request")
                    self.record(416, None, 0)
                    return
                if m.group(1) == "":  # suffix range: the last N bytes
                    start, end = max(0, size - int(m.group(2))), size - 1
                else:
                    start = int(m.group(1))
                    end = min(int(m.group(2)), size - 1) if m.group(2) else size - 1
                if start >= size or start > end:
                    self.send_response(416)
                    self.send_header("Content-Range", "bytes */%d" % size)
                    self.send_header("Content-Length", "0")
                    self.end_headers()
                    self.record(416, [start, end], 0)
                    return
                status = 206
            length = end - start + 1 if size else 0
            self.send_response(status)
            self.send_header("Content-Type", self.guess_type(path))
            self.send_header("Content-Length", str(length))
            if status == 206:
                self.send_header("Content-Range", "bytes %d-%d/%d" % (start, end, size))
            self.end_headers()
            sent = 0
            if not head:
                f.seek(start)
                while sent < length:
                    chunk = f.read(min(1 << 20, length - sent))
                    if not chunk:
                        break
                    self.wfile.write(chunk)
                    sent += len(chunk)
            self.record(status, [start, end] if status == 206 else None, sent)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dir")
    ap.add_argument("--port", type=int, default=8000)
    ap.add_argument("--bind", default="127.0.0.1")
    ap.add_argument("--log", help="append the JSON request log here (default: stderr)")
    ap.add_argument("--port-file", help="write the port here once listening")
    a = ap.parse_args()
    if not os.path.isdir(a.dir):
        print("serve-web: %s is not a folder" % a.dir, file=sys.stderr)
        return 2
    if a.log:
        Handler.log_file = open(a.log, "a", buffering=1)
    handler = lambda *args, **kw: Handler(*args, directory=a.dir, **kw)
    server = http.server.ThreadingHTTPServer((a.bind, a.port), handler)
    port = server.server_address[1]
    if a.port_file:
        tmp = a.port_file + ".tmp"
        with open(tmp, "w") as f:
            f.write("%d\n" % port)
        os.replace(tmp, a.port_file)
    print("serving %s at http://%s:%d/" % (a.dir, a.bind, port), file=sys.stderr, flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
