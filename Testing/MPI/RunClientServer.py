"""SDFCage client-server test driver (plain Python, no VTK).

Starts `mpiexec -np N pvserver --server-port=PORT` on a free loopback port, waits until it
accepts connections, runs the pvpython client script against it, and always stops the server
(its whole process group; Open MPI's own --timeout and pvserver's --timeout as backstops).

Run: python3 RunClientServer.py --mpiexec MPIEXEC [--mpiexec-arg ARG ...] --ranks N
       --pvserver PVSERVER --pvpython PVPYTHON --timeout SECONDS -- CLIENT.py [client args ...]
The client is called as: PVPYTHON CLIENT.py localhost PORT [client args ...]
Exit code: the client's (1 when the server did not come up, 124 on timeout).
"""
import argparse
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def stop(server):
    """SIGTERM to the server's process group, then SIGKILL after 10 s."""
    if server.poll() is not None:
        return
    for sig, wait in ((signal.SIGTERM, 10), (signal.SIGKILL, 5)):
        try:
            os.killpg(server.pid, sig)
        except ProcessLookupError:
            return
        try:
            server.wait(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mpiexec", required=True)
    ap.add_argument("--mpiexec-arg", action="append", default=[])
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--pvserver", required=True)
    ap.add_argument("--pvpython", required=True)
    ap.add_argument("--timeout", type=float, default=500)
    ap.add_argument("client", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    client = [c for c in a.client if c != "--"]
    deadline = time.time() + a.timeout

    version = subprocess.run([a.mpiexec, "--version"], capture_output=True, text=True).stdout
    backstop = ["--timeout", str(int(a.timeout) + 30)] if ("Open MPI" in version or "OpenRTE" in version) else []
    log = tempfile.NamedTemporaryFile(prefix="sdfcage_pvserver_", suffix=".log", delete=False)
    for attempt in range(3):  # a port taken between free_port() and the server's bind: try another
        port = free_port()
        cmd = [a.mpiexec] + a.mpiexec_arg + backstop + ["-np", str(a.ranks), a.pvserver, "--server-port=%d" % port,
                                                         "--timeout=%d" % max(1, int(a.timeout / 60) + 1)]
        print("server:", " ".join(cmd), flush=True)
        log.seek(0)
        log.truncate()
        server = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        up = False
        try:
            while time.time() < deadline and server.poll() is None:
                with open(log.name, errors="replace") as f:
                    text = f.read()
                if "Accepting connection" in text:
                    up = True
                    break
                time.sleep(0.5)
            if not up:
                stop(server)
                with open(log.name, errors="replace") as f:
                    print("server log:\n" + f.read())
                if "bind" in open(log.name, errors="replace").read().lower() and attempt < 2:
                    continue
                print("FAIL: pvserver did not start accepting connections")
                return 1
            print("server up on port %d" % port, flush=True)
            try:
                rc = subprocess.run([a.pvpython] + client[:1] + ["localhost", str(port)] + client[1:],
                                    timeout=max(10.0, deadline - time.time())).returncode
            except subprocess.TimeoutExpired:
                print("FAIL: the client timed out")
                rc = 124
            return rc
        finally:
            stop(server)
            with open(log.name, errors="replace") as f:
                tail = f.read()[-3000:]
            print("--- server log (tail) ---\n" + tail)
    return 1


if __name__ == "__main__":
    code = main()
    sys.exit(code)
