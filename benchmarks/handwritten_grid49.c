/* grid49 written by hand in C: the reference the generated native code is measured against
 * (benchmarks/bench_engine.py compiles it with -O3 and runs it on the same samples).
 *
 * 2 inputs x 7 triangles peaking at -1, -2/3, ..., 1 (feet 1/3 either side), 49 rules
 * "if e is T_i and de is T_j then u is T_clamp(i+j-3)" with AND = MIN, ACT = MIN,
 * ACCU = MAX, and the exact centroid of the accumulated set on [-1, 1]: on each interval
 * between two neighbouring peaks the set is max(min(h_k, falling side of T_k),
 * min(h_k+1, rising side of T_k+1)); every kink and crossing is among
 * {0, 1, 1/2, h_k, 1 - h_k, h_k+1, 1 - h_k+1} (in the interval's own coordinate t), so the
 * set is linear between those points and the trapezoid sums are exact.
 *
 * usage: handwritten_grid49 IN OUT   IN: n rows of "e de" (binary doubles, row-major),
 *        OUT: n doubles.  Prints the loop's CPU time in ns per row to stdout (CPU time:
 *        the benchmark machine is shared).
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

/* the peaks as the FCL writes them: -1 + k/3 in double */
static const double PEAK[7] = {-1.0 + 0.0 / 3.0, -1.0 + 1.0 / 3.0, -1.0 + 2.0 / 3.0, -1.0 + 3.0 / 3.0,
                               -1.0 + 4.0 / 3.0, -1.0 + 5.0 / 3.0, -1.0 + 6.0 / 3.0};

static double tri(double x, double c)
{
    double d = x - c;
    if (d < 0.0) d = -d;
    d = 1.0 - 3.0 * d;
    return d > 0.0 ? d : 0.0;
}

static double grid49(double e, double de)
{
    double me[7], md[7], h[7] = {0}, area = 0.0, mom = 0.0;
    int i, j, k;
    for (i = 0; i < 7; i++) {
        me[i] = tri(e, PEAK[i]);
        md[i] = tri(de, PEAK[i]);
    }
    for (i = 0; i < 7; i++) {
        if (me[i] == 0.0) continue;
        for (j = 0; j < 7; j++) {
            double d = me[i] < md[j] ? me[i] : md[j];
            k = i + j - 3;
            k = k < 0 ? 0 : (k > 6 ? 6 : k);
            if (d > h[k]) h[k] = d;
        }
    }
    for (k = 0; k < 6; k++) {
        double h1 = h[k], h2 = h[k + 1], t[7], f[7], a = PEAK[k], w = PEAK[k + 1] - PEAK[k];
        int n = 7, p, q;
        if (h1 == 0.0 && h2 == 0.0) continue;
        t[0] = 0.0; t[1] = 1.0; t[2] = 0.5; t[3] = h1; t[4] = 1.0 - h1; t[5] = h2; t[6] = 1.0 - h2;
        for (p = 1; p < n; p++) { /* insertion sort */
            double v = t[p];
            for (q = p - 1; q >= 0 && t[q] > v; q--) t[q + 1] = t[q];
            t[q + 1] = v;
        }
        for (p = 0; p < n; p++) {
            double l1 = 1.0 - t[p], l2 = t[p];
            double c1 = l1 < h1 ? l1 : h1, c2 = l2 < h2 ? l2 : h2;
            f[p] = c1 > c2 ? c1 : c2;
        }
        for (p = 0; p + 1 < n; p++) {
            double x0 = a + t[p] * w, x1 = a + t[p + 1] * w, dx = x1 - x0;
            area += 0.5 * dx * (f[p] + f[p + 1]);
            mom += dx * (x0 * (2.0 * f[p] + f[p + 1]) + x1 * (f[p] + 2.0 * f[p + 1])) / 6.0;
        }
    }
    return area > 0.0 ? mom / area : 0.0;
}

int main(int argc, char **argv)
{
    FILE *fin, *fout;
    long n, size, i;
    double *in, *out;
    struct timespec t0, t1;
    if (argc != 3) {
        fprintf(stderr, "usage: %s IN OUT\n", argv[0]);
        return 2;
    }
    fin = fopen(argv[1], "rb");
    if (!fin) return 1;
    fseek(fin, 0, SEEK_END);
    size = ftell(fin);
    fseek(fin, 0, SEEK_SET);
    n = size / (long)(2 * sizeof(double));
    in = malloc((size_t)size);
    out = malloc((size_t)n * sizeof(double));
    if (!in || !out || fread(in, sizeof(double), (size_t)(2 * n), fin) != (size_t)(2 * n)) return 1;
    fclose(fin);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t0);
    for (i = 0; i < n; i++) out[i] = grid49(in[2 * i], in[2 * i + 1]);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t1);
    printf("%.3f\n", ((t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec)) / (double)n);
    fout = fopen(argv[2], "wb");
    if (!fout || fwrite(out, sizeof(double), (size_t)n, fout) != (size_t)n) return 1;
    fclose(fout);
    free(in);
    free(out);
    return 0;
}
