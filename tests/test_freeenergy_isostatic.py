"""BCMD on an isostatic disk packing against its exact jamming simplex (Donev Table 6.1 test,
note sec. 5.2 item 6) at reduced size: 62 backbone disks (64 bidisperse, 2 rattlers removed),
one frozen, M = N_f + 1 = 123 contacts."""

import numpy as np
import pytest
import scipy.sparse as sp

from hardpack.freeenergy.bcmd import run_bcmd
from hardpack.freeenergy.simplex import jamming_simplex, log_simplex_volume
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.neighbours import pairs_within
from hardpack.geometry.packing import Packing

DELTA = 1e-8

# tests/test_jamming_support.jammed_disks() (64 bidisperse disks, size ratio 1.4, seed 3),
# frozen here because building it takes ~1-2 min; repr() round-trips float64 exactly, so the
# contacts stay exact to 1e-12 as that module's self-test checks.
LATTICE = np.array([[20.329632728415366,  0.               ],
       [ 0.               , 20.329632728415366]])
RADII = np.repeat([np.float64(1.5013746543506656), np.float64(1.0724104673933326)], 32)
POSITIONS = np.array([[ 5.721027772314774  , 16.333017155301896  ],
       [11.853619386600702  ,  1.9244362208257528 ],
       [ 9.029116872411095  ,  9.338203698842     ],
       [ 1.9607659509562079 ,  7.9875258315681785 ],
       [12.4119497451306    , 14.832305624475177  ],
       [20.149039205614     ,  5.627850800041486  ],
       [ 6.607806868577178  , 19.54965998162912   ],
       [11.992692321587697  ,  9.821653766526365  ],
       [14.815540494766735  ,  1.430951915192001  ],
       [13.903219106383823  ,  7.4305319226196085 ],
       [ 1.1018545080871345 , 13.272991602939317  ],
       [15.246776604476644  , 15.822386473919588  ],
       [17.30394060015127   ,  9.045537549054597  ],
       [15.423143960104015  , 18.81995181378715   ],
       [ 2.77181363968374   , 15.768535613712006  ],
       [ 5.9251325351569175 , 11.147813081821035  ],
       [ 8.719183907489846  , 12.324915095706693  ],
       [ 3.92777234904376   ,  3.387638213610868  ],
       [10.516016318392266  , 19.56570114649803   ],
       [ 3.7575653510150104 , 18.604870744565513  ],
       [13.838523301126324  , 12.190073367416755  ],
       [20.275957358983806  , 16.78495839497724   ],
       [17.058401495924922  ,  3.427468366511653  ],
       [13.468552445845068  ,  4.457138877914893  ],
       [ 9.890156965300937  ,  4.196289810089371  ],
       [ 8.571269289876943  , 17.277806392365502  ],
       [ 7.97018431630081   ,  6.505014228030533  ],
       [18.843298496973542  , 11.750565099136315  ],
       [10.929584637075362  ,  7.013397107665365  ],
       [17.666004961262203  ,  0.48683553669143725],
       [ 2.9331853377152712 , 10.893342300340331  ],
       [ 8.552553897092501  ,  1.5079220073462822 ],
       [17.917828917803487  , 18.186771890906815  ],
       [19.605735306941064  ,  3.0594190380721686 ],
       [14.850584136002807  ,  9.823619750837743  ],
       [ 6.5488410716827445 ,  8.650743296177152  ],
       [11.136474207784392  , 17.067821673744824  ],
       [11.285715493073544  , 12.518009562515028  ],
       [19.748606749116927  , 19.304139052886438  ],
       [ 4.161843548810037  ,  6.653499122264056  ],
       [ 6.003850790935872  ,  1.8663663260044527 ],
       [ 7.701170885363314  , 14.68881427707877   ],
       [ 1.4969707823084264 , 19.835351158406002  ],
       [19.722815865697854  ,  8.166098919792882  ],
       [ 2.116433400474475  ,  1.559135802809426  ],
       [15.763376681239096  ,  5.651716684991114  ],
       [ 1.3601895353700393 ,  3.5662113018355703 ],
       [16.93928964930501   , 13.648153728597322  ],
       [19.07748014976271   , 14.31367430601918   ],
       [ 2.3869892908723536 ,  5.449277711816783  ],
       [ 7.34971485287223   ,  3.7833446244901907 ],
       [13.248056503517722  , 17.443956025598926  ],
       [ 0.4857795915444732 , 10.09674016218043   ],
       [13.072074839160285  , 19.867254941566134  ],
       [17.730163940067417  ,  6.507289429303202  ],
       [ 5.7886511168565375 , 13.71797702121663   ],
       [ 9.845418159546902  , 14.639211157666841  ],
       [ 5.746820489270421  ,  5.208471461453376  ],
       [16.29187976527479   , 11.411991165633609  ],
       [ 4.408171697127006  ,  8.784127969728079  ],
       [20.327561951742595  ,  1.0397103617641952 ],
       [ 3.6742308061298026 , 13.358138735475098  ],
       [ 4.130551535418692  ,  0.821853644617616  ],
       [17.81094978128304   , 16.04461557250337   ]])


@pytest.fixture(scope="module")
def backbone():
    p = Packing(POSITIONS, RADII, LATTICE)  # contacts exact to 1e-12, next gap > 1e-5
    pl = pairs_within(p, rel_gap=1e-9)
    keep = np.bincount(np.r_[pl.i, pl.j], minlength=p.n_particles) >= 3
    q = p.replace(positions=p.positions[keep], radii=p.radii[keep] * (1 - DELTA))
    pl = pairs_within(q, rel_gap=10 * DELTA)
    m, n, d = pl.i.size, q.n_particles, q.dim
    u = pl.separation / pl.distance[:, None]
    rows = np.repeat(np.arange(m), 2 * d)
    cols = np.concatenate([pl.i[:, None] * d + np.arange(d), pl.j[:, None] * d + np.arange(d)], 1)
    vals = np.concatenate([-u, u], 1).ravel()
    at = sp.csr_matrix((vals, (rows, cols.ravel())), shape=(m, n * d))[:, d:]  # particle 0 frozen
    return q, at, pl.distance - pl.contact, pl.contact


def test_packing_is_isostatic_and_formulas_agree(backbone):
    q, at, gaps, contact = backbone
    assert at.shape == (2 * (q.n_particles - 1) + 1, 2 * (q.n_particles - 1))
    js = jamming_simplex(at.T, n_eff=q.n_particles - 1)  # Eq. 6.3, unit gaps
    # Eq. 6.5 on the mirrored system -A^T x <= e (chapter sign convention): same volume
    assert log_simplex_volume(-at, np.ones(at.shape[0])) == pytest.approx(js.log_volume, rel=1e-10)
    # shrinking exact contacts by (1 - delta) leaves relative gaps delta / (1 - delta) (the
    # maker's contacts are exact to 1e-12 absolute, i.e. 1e-4 relative to delta)
    np.testing.assert_allclose(gaps / contact, DELTA / (1 - DELTA), rtol=1e-3)


def test_bcmd_matches_exact_simplex(backbone):
    # exact ln(V / V_min) per moving disk from the linearised simplex with the actual gaps
    # (Eq. 6.5; linearisation error O(delta)); BCMD with Table 6.1 row-1 parameters
    # (gamma0 = 0.1, theta = 1) at dmu_max = 100 delta (measured difference -0.0025; -0.0026 at
    # 1000 delta, so the start is already unconstrained by the cells); the paper's scatter at N = 1000 is ~2e-3 and grows at small N, so the
    # tolerance is 0.01 (0.3 %).
    q, at, gaps, _contact = backbone
    n_eff = q.n_particles - 1
    log_cells = np.sum(np.log(ball_volume(DELTA / (1 - DELTA) * q.radii[1:], 2)))
    exact = (log_simplex_volume(-at, gaps) - log_cells) / n_eff
    res = run_bcmd(q, dmu_max=100 * DELTA, gamma0=0.1, theta=1.0, seed=1)
    assert res.dataset.attrs["dmu_min"] == pytest.approx(DELTA / (1 - DELTA), rel=1e-4)
    assert res.delta_f == pytest.approx(exact, abs=0.01)
