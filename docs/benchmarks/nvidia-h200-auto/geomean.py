"""Geometric mean of fps over RC-t for auto and for the modes leaping strategy, from the
"Leaping against RC-t" table of tables.md files. Usage: python3 geomean.py */tables.md"""
import sys,math,re
leap={'dvr':'RC-s-df','iso':'RC-s-df','xray':'RC-s-df','xray-attenuation':'RC-s-df','mip':'RC-s','minip':'RC-s'}
for f in sys.argv[1:]:
    t=open(f).read(); sec=t[t.index('## Leaping against RC-t'):t.index('## Environment')]
    A=[];L=[];lose=0
    for line in sec.splitlines():
        c=[x.strip() for x in line.split('|')]
        if len(c)<8 or c[1] in('dataset','---'): continue
        try: v=float(c[6])
        except: continue
        if c[5].startswith('auto'): A.append(v)
        elif c[5]==leap.get(c[2]):
            L.append(v); lose+= v<0.98
    g=lambda a: math.exp(sum(map(math.log,a))/len(a)) if a else float('nan')
    print(f, 'auto n=%d geomean %.3f min %.2f | leaping n=%d geomean %.3f min %.2f, <0.98: %d'%(len(A),g(A),min(A) if A else 0,len(L),g(L),min(L) if L else 0,lose))
