/* robot.h: what the static extractor driver (driver.cpp) needs of an arm, provided at link time
 * by robot.c (with the arm's generated <robot>_kinds.h) and the arm's generated
 * <robot>_parameters.c, built in double. */
#ifndef DYNGEN_ROBOT_H
#define DYNGEN_ROBOT_H

#ifdef __cplusplus
extern "C" {
#endif

/* One kind of base coefficients: pi(p) (rank values) and d pi / d p (rank x 10N, row-major). */
typedef struct {
    const char *name; /* gravity, inertia or full */
    int rank;
    void (*pi)(const double *p, double *pi);
    void (*jacobian)(const double *p, double *J);
} dyngen_kind;

extern const int dyngen_links; /* N: the arm has 10 N dynamic parameters */
extern const int dyngen_kind_count;
extern const dyngen_kind dyngen_kinds[];
void dyngen_standard_from_dynamic(const double *p, double *s);

#ifdef __cplusplus
}
#endif

#endif /* DYNGEN_ROBOT_H */
