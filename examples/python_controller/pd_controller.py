#!/usr/bin/env python3
"""A PD controller for the EXOwheel twin, written from outside the project.

Python 3, standard library only (socket, struct). Written from DESIGN.md's "The CAN transport
between processes" (the link's frames, the lockstep cycle) and protocol/exotwin.dbc (the device's
messages); it shares no code with exotwin. It drives `exotwin serve SCENARIO --bus udp:HOST:PORT`
in lockstep:

  python3 pd_controller.py --bus udp:127.0.0.1:47000 --winter data/WinterTableA1.txt

The link: UDP, the twin on HOST:PORT, this controller on HOST:PORT+1. A datagram carries 1 to 64
frames of 16 bytes, SocketCAN's struct can_frame: can_id u32 little-endian (11-bit id), can_dlc u8,
3 bytes zero, data[8].

What it does, per the frame table: answers each NMT start (0x000, data[0] 1) with a ready frame
(0x701); reads the joint modules' status (0x180 hip, 0x181 knee: angle int32 * 1e-6 rad, DBC
JM_*_STATUS) with the receive stamps (0x7F1) the twin puts before them; on each SYNC (0x080, the
tick's simulated time t) computes

  tau_j = kp_j (q_ref_j - q_j) + kd_j (qd_ref_j - qd_j),  clamped to +-torque_limit,

qd_j the difference quotient of the last two angle samples over their stamps, q_ref the reference
below; sends the two joint commands (0x100 hip, 0x101 knee: torque int16 * 0.01 N m, counter,
enable; DBC JM_*_CMD), the telemetry (0x780 + i, IEEE-754 doubles: estimated q, torque sensors,
commands, reference q, safety state 0, EMG 0) and the done frame (0x7F0, t echoed), all in one
datagram; exits 0 on NMT stop (data[0] 2).

The reference is the project's gait pattern rebuilt from its definition (controller/trajectory.h
GaitTrajectory, FadeInTrajectory): Winter's Table A.1 markers -> hip = thigh angle to the downward
vertical, knee = shank minus thigh; the stride period detected as the lag of least mismatch (refined
by a parabola); a 10-harmonic Fourier series fitted by least squares, phase 0 at 0.386 s of the
recording, time-scaled to the output stride period, the knee shifted by -3 deg; the first `ramp`
seconds faded in from the start pose by the quintic smoothstep 10s^3 - 15s^4 + 6s^5.
"""
import argparse
import math
import socket
import struct
import sys

FRAME = struct.Struct("<IB3x8s")  # struct can_frame
ID_NMT, ID_SYNC, ID_READY, ID_DONE, ID_STAMP = 0x000, 0x080, 0x701, 0x7F0, 0x7F1
ID_TELEMETRY = 0x780
ID_STATUS = {0x180: 0, 0x181: 1}   # JM_HIP_STATUS, JM_KNEE_STATUS -> joint
ID_COMMAND = (0x100, 0x101)        # JM_HIP_CMD, JM_KNEE_CMD
MAX_FRAMES = 64


def frame(can_id, data):
    return FRAME.pack(can_id, len(data), bytes(data).ljust(8, b"\0"))


def double_frame(can_id, v):
    return frame(can_id, struct.pack("<d", v))


# ------------------------------------------------------------------ the gait reference

def winter_angles(path):
    """(time, hip, knee) of Winter's Table A.1 (columns FRAME TIME RIB x y HIP x y KNEE x y FIBULA x y ANKLE x y)."""
    time, hip, knee = [], [], []
    with open(path) as f:
        for line in f:
            s = line.strip()
            if not s or s[0] in "'#":
                continue
            v = [float(x) for x in s.split()[:12]]
            thigh = math.atan2(v[6] - v[4], v[5] - v[7])
            shank = math.atan2(v[10] - v[6], v[7] - v[11])
            time.append(v[1])
            hip.append(thigh)
            knee.append(shank - thigh)
    return time, hip, knee


def stride_frames(hip, knee):
    n = len(hip)
    lo, hi = max(2, n // 4), n - max(10, n // 5)

    def mismatch(lag):
        return sum((hip[i + lag] - hip[i]) ** 2 + (knee[i + lag] - knee[i]) ** 2 for i in range(n - lag)) / (n - lag)

    e = {lag: mismatch(lag) for lag in range(lo, hi + 1)}
    best = min(e, key=e.get)
    em, e0, ep = mismatch(best - 1), e[best], mismatch(best + 1)
    den = em - 2 * e0 + ep
    return best + (min(0.5, max(-0.5, 0.5 * (em - ep) / den)) if den > 0 else 0.0)


def solve(a, b):
    """Gaussian elimination with partial pivoting."""
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        for r in range(c + 1, n):
            f = m[r][c] / m[c][c]
            for k in range(c, n + 1):
                m[r][k] -= f * m[c][k]
    x = [0.0] * n
    for r in range(n - 1, -1, -1):
        x[r] = (m[r][n] - sum(m[r][k] * x[k] for k in range(r + 1, n))) / m[r][r]
    return x


def fourier_fit(t, y, f0, harmonics):
    """[c0, a1, b1, a2, b2, ...] of y ~ c0 + sum a_k sin(2 pi k f0 t) + b_k cos(2 pi k f0 t) (least squares)."""
    rows = []
    for ti in t:
        r = [1.0]
        for k in range(1, harmonics + 1):
            r += [math.sin(2 * math.pi * k * f0 * ti), math.cos(2 * math.pi * k * f0 * ti)]
        rows.append(r)
    n = len(rows[0])
    ata = [[sum(r[i] * r[j] for r in rows) for j in range(n)] for i in range(n)]
    aty = [sum(r[i] * yi for r, yi in zip(rows, y)) for i in range(n)]
    return solve(ata, aty)


class GaitReference:
    def __init__(self, winter_path, stride_period, ramp, harmonics=10, phase_origin=0.386,
                 knee_offset=-3 * math.pi / 180):
        time, hip, knee = winter_angles(winter_path)
        dt = (time[-1] - time[0]) / (len(time) - 1)
        f_data = 1.0 / (stride_frames(hip, knee) * dt)
        tau = [ti - phase_origin for ti in time]
        self.coef = [fourier_fit(tau, hip, f_data, harmonics), fourier_fit(tau, knee, f_data, harmonics)]
        self.coef[1][0] += knee_offset
        self.f0, self.ramp = 1.0 / stride_period, ramp
        self.start = [self.inner(0.0, j)[0] for j in (0, 1)]

    def inner(self, t, j):
        c = self.coef[j]
        w = 2 * math.pi * self.f0
        phase = w * t
        q, qd = c[0], 0.0
        for k in range(1, (len(c) - 1) // 2 + 1):
            a, b = c[2 * k - 1], c[2 * k]
            s, co = math.sin(k * phase), math.cos(k * phase)
            q += a * s + b * co
            qd += k * w * (a * co - b * s)
        return q, qd

    def __call__(self, t, j):
        """(q, qd) of joint j (0 hip, 1 knee) at t (s)."""
        if t >= self.ramp or self.ramp <= 0:
            return self.inner(t, j)
        if t <= 0:
            return self.start[j], 0.0
        q, qd = self.inner(t, j)
        s = t / self.ramp
        w = s * s * s * (10 - 15 * s + 6 * s * s)
        dw = 30 * s * s * (1 - s) ** 2 / self.ramp
        e = q - self.start[j]
        return self.start[j] + w * e, dw * e + w * qd


# ------------------------------------------------------------------ the link and the loop

def parse_bus(text):
    if not text.startswith("udp:"):
        sys.exit("pd_controller: --bus: expected udp:HOST:PORT, got '%s'" % text)
    host, port = text[4:].rsplit(":", 1)
    host = "127.0.0.1" if host == "localhost" else host
    return host, int(port)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bus", required=True, help="udp:HOST:PORT of exotwin serve")
    ap.add_argument("--winter", required=True, help="Winter's Table A.1 (data/WinterTableA1.txt)")
    ap.add_argument("--kp", type=float, nargs=2, default=[600.0, 400.0], help="N m/rad, hip knee")
    ap.add_argument("--kd", type=float, nargs=2, default=[30.0, 15.0], help="N m s/rad, hip knee")
    ap.add_argument("--torque-limit", type=float, default=100.0, help="N m")
    ap.add_argument("--stride-period", type=float, default=2.0, help="s")
    ap.add_argument("--ramp", type=float, default=2.0, help="s of fade-in")
    ap.add_argument("--timeout", type=float, default=30.0, help="s without a frame before giving up")
    a = ap.parse_args()
    host, port = parse_bus(a.bus)
    ref = GaitReference(a.winter, a.stride_period, a.ramp)

    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind((host, port + 1))
    sock.settimeout(a.timeout)
    twin = (host, port)
    q = [None, None]      # last angle sample per joint (rad) and its stamp (s)
    q_prev = [None, None]
    torque_sensor = [0.0, 0.0]
    stamp = None
    counter = 0
    ticks = 0
    running = False
    while True:
        try:
            data, sender = sock.recvfrom(16 * MAX_FRAMES + 16)
        except socket.timeout:
            sys.exit("pd_controller: no frame from the twin within %g s" % a.timeout)
        if sender != twin or len(data) == 0 or len(data) % 16 or len(data) > 16 * MAX_FRAMES:
            continue  # another sender, or not a whole number of frames: dropped
        for i in range(0, len(data), 16):
            can_id, dlc, payload = FRAME.unpack_from(data, i)
            if can_id == ID_NMT and dlc >= 1:
                if payload[0] == 0x01:  # start: a fresh loop for the trial, answered by a ready frame
                    trial = payload[2] if dlc >= 3 else 0
                    seq = payload[3:5] if dlc >= 5 else b"\0\0"
                    q, q_prev, stamp, running = [None, None], [None, None], None, True
                    sock.sendto(frame(ID_READY, bytes([0x05, trial]) + seq), twin)
                elif payload[0] == 0x02:  # stop: the session is over
                    print("pd_controller: run over (NMT stop): %d ticks" % ticks, file=sys.stderr)
                    return 0
            elif can_id == ID_STAMP and dlc == 8:
                stamp = struct.unpack("<d", payload)[0]
            elif can_id in ID_STATUS and dlc == 8:
                j = ID_STATUS[can_id]
                angle = struct.unpack_from("<i", payload, 0)[0] * 1e-6
                torque_sensor[j] = struct.unpack_from("<h", payload, 4)[0] * 0.015
                q_prev[j], q[j] = q[j], (angle, stamp)
                stamp = None
            elif can_id == ID_SYNC and dlc == 8 and running:
                t = struct.unpack("<d", payload)[0]
                out, cmd, ref_q = [], [0.0, 0.0], [0.0, 0.0]
                for j in (0, 1):
                    ref_q[j], ref_qd = ref(t, j)
                    if q[j] is None:
                        continue  # no sample yet: zero torque, drive enabled
                    qd = 0.0
                    if q_prev[j] is not None and q[j][1] is not None and q_prev[j][1] is not None \
                            and q[j][1] > q_prev[j][1]:
                        qd = (q[j][0] - q_prev[j][0]) / (q[j][1] - q_prev[j][1])
                    tau = a.kp[j] * (ref_q[j] - q[j][0]) + a.kd[j] * (ref_qd - qd)
                    cmd[j] = max(-a.torque_limit, min(a.torque_limit, tau))
                counter = (counter + 1) & 0xFF
                for j in (0, 1):
                    raw = max(-32768, min(32767, int(round(cmd[j] / 0.01))))
                    out.append(frame(ID_COMMAND[j], struct.pack("<hBB", raw, counter, 1)))
                est = [q[j][0] if q[j] else 0.0 for j in (0, 1)]
                telemetry = est + torque_sensor + cmd + ref_q + [0.0] + [0.0] * 5
                out += [double_frame(ID_TELEMETRY + i, v) for i, v in enumerate(telemetry)]
                out.append(double_frame(ID_DONE, t))
                sock.sendto(b"".join(out), twin)
                ticks += 1


if __name__ == "__main__":
    sys.exit(main())
