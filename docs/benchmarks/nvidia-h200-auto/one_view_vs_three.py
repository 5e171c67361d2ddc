"""Replays auto's choice offline from a benchmark's frames.csv(.gz): for every dataset, mode and
size, RC-t and the mode's leaping strategy timed on some of the orbit's views decide, with a
margin m (leaping only if faster by more than m), and the chosen strategy's orbit median is
compared with RC-t's. Usage: python3 one_view_vs_three.py one-view/frames.csv.gz"""
import csv, gzip, sys, statistics as st, collections
opener = gzip.open if sys.argv[1].endswith('.gz') else open
rows = list(csv.DictReader(opener(sys.argv[1], 'rt')))
T=collections.defaultdict(dict)
for r in rows:
    if r['sweep']=='true': continue
    T[(r['dataset'],r['mode'],r['width'])].setdefault(r['strategy'],{})[int(r['view'])]=float(r['ms'])
leap={'dvr':'RC-s-df','iso':'RC-s-df','xray':'RC-s-df','xray-attenuation':'RC-s-df','mip':'RC-s','minip':'RC-s'}
def med(d): return st.median(d.values())
cells=[]
for k,s in sorted(T.items()):
    L=leap[k[1]]
    if L not in s or 'RC-t' not in s: continue
    cells.append((k,s['RC-t'],s[L],s.get('auto')))
print(len(cells),'cells')
for views in ([0],[0,4,8],[0,3,6,9],list(range(12))):
  for m in (0,0.03,0.05,0.1,0.15):
    ok=0; lg=[]; bad=[]
    for k,rt,lp,au in cells:
        a=sum(lp[v] for v in views); b=sum(rt[v] for v in views)
        choose_leap = a < b*(1-m)
        ratio = med(rt)/med(lp) if choose_leap else 1.0
        lg.append(ratio)
        if ratio>=0.98: ok+=1
        else: bad.append((k,round(ratio,2)))
    import math
    gm=math.exp(sum(math.log(x) for x in lg)/len(lg))
    print(views if len(views)<12 else 'all', m, ok, 'geomean %.3f'%gm, bad[:6])
# oracle
lg=[max(1.0,med(rt)/med(lp)) for k,rt,lp,au in cells]
import math
print('oracle geomean %.3f'%math.exp(sum(math.log(x) for x in lg)/len(lg)))
print('--- phases of 3 views 120 deg apart')
for ph in range(4):
  for m in (0,0.03,0.05,0.08):
    views=[ph,ph+4,ph+8]
    ok=0; bad=[]
    for k,rt,lp,au in cells:
        a=sum(lp[v] for v in views); b=sum(rt[v] for v in views)
        ratio = med(rt)/med(lp) if a < b*(1-m) else 1.0
        if ratio>=0.98: ok+=1
        else: bad.append((k,round(ratio,3)))
    print(views,m,ok,bad)
