import csv,sys,os,glob
a,b=sys.argv[1],sys.argv[2]
timing=lambda c: any(t in c for t in ("_ms","ms_","wall","time_vs","shadow_ray_share","gpu","ratio_of_times")) or c.endswith("ms")
tot=same=0; diffs=[]
for fa in sorted(glob.glob(os.path.join(a,"**","*.csv"),recursive=True)):
    rel=os.path.relpath(fa,a); fb=os.path.join(b,rel)
    if not os.path.exists(fb): diffs.append(f"{rel}: missing in after"); continue
    ra=list(csv.DictReader(open(fa))); rb=list(csv.DictReader(open(fb)))
    if len(ra)!=len(rb): diffs.append(f"{rel}: {len(ra)} vs {len(rb)} rows"); continue
    cols=[c for c in (ra[0].keys() if ra else []) if not timing(c)]
    for i,(x,y) in enumerate(zip(ra,rb)):
        for c in cols:
            tot+=1
            if c not in y: diffs.append(f"{rel}: column {c} missing after"); continue
            if x[c]==y[c]: same+=1
            else: diffs.append(f"{rel} row {i} {c}: {x[c]} vs {y[c]}")
print(f"deterministic cells: {tot}, identical: {same}")
for d in diffs[:60]: print(d)
print(f"{len(diffs)} differences")
