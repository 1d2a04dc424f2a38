"""summary.json's per-frame series (a heat model's temperatures) stay bounded however many
frames a run saves: every frame while they fit, then every 2nd, 4th, ... and the last."""

from fibrelmp.granular_run.frames import ThinnedSeries


def _frames(series: ThinnedSeries, n: int) -> list[int]:
    for k in range(n):
        series.append({"step": k})
    return [e["step"] for e in series.entries()]


def test_every_frame_while_they_fit():
    assert _frames(ThinnedSeries(limit=8), 8) == list(range(8))
    assert _frames(ThinnedSeries(limit=8), 0) == []


def test_a_long_series_keeps_a_regular_stride_and_the_last_frame():
    for n in (9, 100, 1000, 12345):
        s = ThinnedSeries(limit=8)
        kept = _frames(s, n)
        assert len(kept) <= 9 + 1
        assert kept[-1] == n - 1                       # the last frame is always there
        body = kept[:-1] if (n - 1) % s.every else kept
        assert body == list(range(0, n, s.every))      # frames 0, every, 2·every, ...
        assert len(body) > 8 // 2                      # thinned only as far as needed


def test_the_store_does_not_grow_with_frames():
    s = ThinnedSeries(limit=1024)
    _frames(s, 200_000)
    assert len(s.kept) <= 1024 and s.every == 256
