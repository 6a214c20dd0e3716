#!/usr/bin/env python3
# Prints the measured period of both pendulums against the small-amplitude closed form
# T = 2 pi sqrt(I_pivot / (m g L/2)) (1 + theta0^2/16). Usage: period.py OUTDIR
import csv, math, sys
rows=list(csv.DictReader(open(sys.argv[1]+'/probes.csv')))
rho, d, L = 7870, 0.006, 0.3
m = rho*math.pi*d*d/4*L; r=d/2
Ip = m*L*L/12 + m*r*r/4 + m*(L/2)**2
T = 2*math.pi*math.sqrt(Ip/(m*9.81*L/2))*(1+0.05**2/16)
for name, x0 in (('tip_rod',0.0),('tip_block',1.0)):
    xs=[(float(r['time']), float(r[name+'.position.x'])-x0) for r in rows]
    cr=[t0+(t1-t0)*(-a)/(b-a) for (t0,a),(t1,b) in zip(xs,xs[1:]) if a<0<=b]
    Tm=(cr[-1]-cr[0])/(len(cr)-1)
    print(name, 'rel period error', (Tm-T)/T)
