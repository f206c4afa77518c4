#!/usr/bin/env python3
"""Re-runs points of a `fado-sim sweep reversal` envelope (scripts/lock-sweeps-preset.sh) with
full-rate traces and prints the state at the loss onset t0, at t0 + 20 ms and at the first
LOCK_LOST: angle error, true/estimated/reference speed as fractions of the rated speed,
|n* - n̂|, i_q* / rated current, mode, LOCK_LOST and the estimator's `lock` status
(docs/lock.md "Other motors"). The load profile is the reversal's ([1.2 s, 0], [1.7 s, T_L]).

usage: scripts/lock-trace-points.py PRESET OUT/VARIANT.toml OUT/VARIANT/sweep.csv POINT...
"""
import csv, os, shutil, subprocess, sys, tempfile, tomllib
ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..')
preset,vt,sweep=sys.argv[1:4]
rows={r['point']:r for r in csv.DictReader(open(sweep))}
m=tomllib.load(open(os.path.join(ROOT, 'motors', preset + '.toml'),'rb'))['motor']
ri=m['rated_current']; rn=m['rated_speed_rpm']
for pt in sys.argv[4:]:
    row=rows[pt]
    tmp = tempfile.mkdtemp()
    cfg = os.path.join(tmp, 'point.toml')
    with open(cfg,'w') as f:
        f.write(open(vt).read())
        f.write(f"\n[mismatch]\nrs_ratio = {1+float(row['rs_error'])}\nlq_ratio = {1+float(row['lq_error'])}\nflux_linkage_ratio = {1+float(row['flux_linkage_error'])}\n")
        f.write(f"\n[load.torque]\npoints = [[1.2, 0.0], [1.7, {row['load_torque']}]]\n\n[simulation]\ndecimation = 1\n")
    out = os.path.join(tmp, 'out')
    subprocess.run([os.path.join(ROOT, 'target/release/fado-sim'),'run','reversal','--config',cfg,'--out',out],capture_output=True)
    r=list(csv.DictReader(open(out+'/traces.csv'))); shutil.rmtree(tmp)
    def at(t):
        x=min(r,key=lambda x:abs(float(x['time'])-t)); ff=int(float(x['fault_flags']))
        return f"t={t:.3f} err={float(x['angle_error']):+.2f} n={float(x['speed_rpm'])/rn:+.4f} n̂={float(x['speed_hat_rpm'])/rn:+.4f} n*={float(x['speed_ref_rpm'])/rn:+.4f} |n*-n̂|={abs(float(x['speed_ref_rpm'])-float(x['speed_hat_rpm']))/rn:.4f} iq*={float(x['i_q_ref'])/ri:+.2f} {'lim' if ff&64 else 'kdf'} {'LOST' if ff&128 else '-'} st={x['lock']}"
    print(f"#{pt} rs{float(row['rs_error']):+.3f} lf{float(row['flux_linkage_error']):+.3f} lq{float(row['lq_error']):+.3f} TL{float(row['load_torque']):.2f} max{float(row['max_angle_error_run']):.2f} pass={row['passed']}")
    ts=[]
    if row['loss_onset_time']: t0=float(row['loss_onset_time']); ts+=[t0,t0+0.02]
    fl=[float(x['time']) for x in r if int(float(x['fault_flags']))&128]
    if fl: ts.append(fl[0])
    for t in ts: print('   ',at(t))
