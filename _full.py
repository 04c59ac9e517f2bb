import time, json, sys
from validation.studies.coating_winkler import run_coating_winkler
from validation.studies import write_json
t0=time.perf_counter()
d = run_coating_winkler(quick=False, fem=True, progress=lambda l,k,n: print(k, n, l, round(time.perf_counter()-t0,1), flush=True))
write_json("/tmp/cw/coating_winkler.json", d)
print("total", time.perf_counter()-t0)
