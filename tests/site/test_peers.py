"""The peers block: chosen matchers of one run side by side, from its headline.csv."""

from pathlib import Path

from tfloc.site.collect import SiteData
from tfloc.site.markdown import refresh

HEAD = ("mode,scope,rank,matcher,measure,value_pct,lo_pct,hi_pct,n,error_cm,error,cpu_ms,verdict,next_matcher,"
        "p_holm,truth_free_score,self_auc\n"
        "sequence,all,1,a,tracked,90.0,85,95,100,3.21,APE RMSE,0.5,ahead,b,0.01,,\n"
        "sequence,all,2,b,tracked,50.0,45,55,100,30.0,APE RMSE,12.0,,,,,\n"
        "sequence,rec-1,1,b,tracked,60.0,50,70,50,20.0,APE RMSE,11.0,,,,,\n")


def test_the_peers_block_reads_the_runs_headline(tmp_path: Path) -> None:
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "headline.csv").write_text(HEAD)
    text = "x\n<!-- tfloc:begin peers.run.b.a -->\nold\n<!-- tfloc:end peers.run.b.a -->\n"
    out = refresh(text, SiteData(tmp_path, [], {}))
    assert "old" not in out and "| recording | `b` | `a` |" in out
    assert "| pooled | 50.0 % (#2 of 2) · 30.0 cm · 12 ms | 90.0 % (#1 of 2) · 3.2 cm · 0.5 ms |" in out
    assert "| rec-1 | 60.0 % (#1 of 1) · 20.0 cm · 11 ms | — |" in out
    assert "Not yet" in refresh(text.replace("peers.run", "peers.none"), SiteData(tmp_path, [], {}))
