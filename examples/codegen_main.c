#include <stdio.h>
#include "Fuzzy_FB.h"

int main(void)
{
    Fuzzy_FB fb;
    Fuzzy_FB_init(&fb);
    fb.temp = 10.0;
    fb.pressure = 60.0;
    unsigned char info = Fuzzy_FB_step(&fb);
    printf("valve = %.6f, INFO = %d\n", fb.valve, info);
    fb.FZ_valve_S[2] = 50.0;                 /* retune: inlet singleton 100 -> 50 */
    Fuzzy_FB_step(&fb);
    printf("valve = %.6f\n", fb.valve);
    return 0;
}
