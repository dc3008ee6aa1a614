/*
 * Jos Stam's stable fluids, transcribed routine for routine from the code of his *Real-Time Fluid
 * Dynamics for Games* (GDC 2003).
 *
 * Driver: a fixed source pattern (the same as `anim_fluid::stam::source_pattern`), stepped
 * with sim_main's order (vel_step, then dens_step).
 *
 *   stable_fluids dump N STEPS OUT   writes dens, u, v ((N+2)^2 f32 each, little endian) to OUT
 *   stable_fluids time N STEPS       prints {"n":N,"steps":STEPS,"per_step_s":...}
 *
 * Build for the bitwise check with `cc -O2 -ffp-contract=off`, for timing with `-O3`.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define IX(i,j) ((i)+(N+2)*(j))
#define SWAP(x0,x) {float * tmp=x0;x0=x;x=tmp;}
#define FOR_EACH_CELL for ( i=1 ; i<=N ; i++ ) { for ( j=1 ; j<=N ; j++ ) {
#define END_FOR }}

void add_source ( int N, float * x, float * s, float dt )
{
	int i, size=(N+2)*(N+2);
	for ( i=0 ; i<size ; i++ ) x[i] += dt*s[i];
}

void set_bnd ( int N, int b, float * x )
{
	int i;
	for ( i=1 ; i<=N ; i++ ) {
		x[IX(0  ,i)] = b==1 ? -x[IX(1,i)] : x[IX(1,i)];
		x[IX(N+1,i)] = b==1 ? -x[IX(N,i)] : x[IX(N,i)];
		x[IX(i,0  )] = b==2 ? -x[IX(i,1)] : x[IX(i,1)];
		x[IX(i,N+1)] = b==2 ? -x[IX(i,N)] : x[IX(i,N)];
	}
	x[IX(0  ,0  )] = 0.5f*(x[IX(1,0  )]+x[IX(0  ,1)]);
	x[IX(0  ,N+1)] = 0.5f*(x[IX(1,N+1)]+x[IX(0  ,N)]);
	x[IX(N+1,0  )] = 0.5f*(x[IX(N,0  )]+x[IX(N+1,1)]);
	x[IX(N+1,N+1)] = 0.5f*(x[IX(N,N+1)]+x[IX(N+1,N)]);
}

void lin_solve ( int N, int b, float * x, float * x0, float a, float c )
{
	int i, j, k;
	for ( k=0 ; k<20 ; k++ ) {
		FOR_EACH_CELL
			x[IX(i,j)] = (x0[IX(i,j)] + a*(x[IX(i-1,j)]+x[IX(i+1,j)]+x[IX(i,j-1)]+x[IX(i,j+1)]))/c;
		END_FOR
		set_bnd ( N, b, x );
	}
}

void diffuse ( int N, int b, float * x, float * x0, float diff, float dt )
{
	float a=dt*diff*N*N;
	lin_solve ( N, b, x, x0, a, 1+4*a );
}

void advect ( int N, int b, float * d, float * d0, float * u, float * v, float dt )
{
	int i, j, i0, j0, i1, j1;
	float x, y, s0, t0, s1, t1, dt0;
	dt0 = dt*N;
	FOR_EACH_CELL
		x = i-dt0*u[IX(i,j)]; y = j-dt0*v[IX(i,j)];
		if (x<0.5f) x=0.5f; if (x>N+0.5f) x=N+0.5f; i0=(int)x; i1=i0+1;
		if (y<0.5f) y=0.5f; if (y>N+0.5f) y=N+0.5f; j0=(int)y; j1=j0+1;
		s1 = x-i0; s0 = 1-s1; t1 = y-j0; t0 = 1-t1;
		d[IX(i,j)] = s0*(t0*d0[IX(i0,j0)]+t1*d0[IX(i0,j1)])+
					 s1*(t0*d0[IX(i1,j0)]+t1*d0[IX(i1,j1)]);
	END_FOR
	set_bnd ( N, b, d );
}

void project ( int N, float * u, float * v, float * p, float * div )
{
	int i, j;
	FOR_EACH_CELL
		div[IX(i,j)] = -0.5f*(u[IX(i+1,j)]-u[IX(i-1,j)]+v[IX(i,j+1)]-v[IX(i,j-1)])/N;
		p[IX(i,j)] = 0;
	END_FOR
	set_bnd ( N, 0, div ); set_bnd ( N, 0, p );
	lin_solve ( N, 0, p, div, 1, 4 );
	FOR_EACH_CELL
		u[IX(i,j)] -= 0.5f*N*(p[IX(i+1,j)]-p[IX(i-1,j)]);
		v[IX(i,j)] -= 0.5f*N*(p[IX(i,j+1)]-p[IX(i,j-1)]);
	END_FOR
	set_bnd ( N, 1, u ); set_bnd ( N, 2, v );
}

void dens_step ( int N, float * x, float * x0, float * u, float * v, float diff, float dt )
{
	add_source ( N, x, x0, dt );
	SWAP ( x0, x ); diffuse ( N, 0, x, x0, diff, dt );
	SWAP ( x0, x ); advect ( N, 0, x, x0, u, v, dt );
}

void vel_step ( int N, float * u, float * v, float * u0, float * v0, float visc, float dt )
{
	add_source ( N, u, u0, dt ); add_source ( N, v, v0, dt );
	SWAP ( u0, u ); diffuse ( N, 1, u, u0, visc, dt );
	SWAP ( v0, v ); diffuse ( N, 2, v, v0, visc, dt );
	project ( N, u, v, u0, v0 );
	SWAP ( u0, u ); SWAP ( v0, v );
	advect ( N, 1, u, u0, u0, v0, dt ); advect ( N, 2, v, v0, u0, v0, dt );
	project ( N, u, v, u0, v0 );
}

/* The fixed source pattern: a block of (2r+1) x (r+1) cells at the bottom centre (r = max(N/16, 1))
 * emits density 100 and an upward force 5; a sideways force of +-2 flips every 25 steps. */
static void get_force_source ( int N, int step, float * d, float * u, float * v )
{
	int i, j, size=(N+2)*(N+2);
	int c = N/2, r = N/16 > 1 ? N/16 : 1;
	for ( i=0 ; i<size ; i++ ) { d[i] = u[i] = v[i] = 0.0f; }
	for ( i=c-r ; i<=c+r ; i++ ) for ( j=2 ; j<=2+r ; j++ ) {
		d[IX(i,j)] = 100.0f;
		v[IX(i,j)] = 5.0f;
		u[IX(i,j)] = ((step/25)%2) ? -2.0f : 2.0f;
	}
}

int main ( int argc, char ** argv )
{
	const float dt = 0.1f, diff = 0.0001f, visc = 0.0001f;
	int N, steps, s, size;
	float *u, *v, *u_prev, *v_prev, *dens, *dens_prev;
	if ( argc < 4 ) { fprintf(stderr, "usage: %s dump|time N STEPS [OUT]\n", argv[0]); return 2; }
	N = atoi(argv[2]); steps = atoi(argv[3]);
	if ( N < 1 || steps < 0 ) { fprintf(stderr, "bad N or STEPS\n"); return 2; }
	size = (N+2)*(N+2);
	u = calloc(size, sizeof(float)); v = calloc(size, sizeof(float));
	u_prev = calloc(size, sizeof(float)); v_prev = calloc(size, sizeof(float));
	dens = calloc(size, sizeof(float)); dens_prev = calloc(size, sizeof(float));
	if ( !u || !v || !u_prev || !v_prev || !dens || !dens_prev ) { fprintf(stderr, "out of memory\n"); return 1; }
	if ( strcmp(argv[1], "dump") == 0 ) {
		FILE * f;
		if ( argc < 5 ) { fprintf(stderr, "dump needs OUT\n"); return 2; }
		for ( s=0 ; s<steps ; s++ ) {
			get_force_source ( N, s, dens_prev, u_prev, v_prev );
			vel_step ( N, u, v, u_prev, v_prev, visc, dt );
			dens_step ( N, dens, dens_prev, u, v, diff, dt );
		}
		f = fopen(argv[4], "wb");
		if ( !f ) { fprintf(stderr, "cannot write %s\n", argv[4]); return 1; }
		fwrite(dens, sizeof(float), size, f); fwrite(u, sizeof(float), size, f); fwrite(v, sizeof(float), size, f);
		fclose(f);
	} else {
		struct timespec t0, t1;
		/* warm-up steps, not timed */
		for ( s=0 ; s<5 ; s++ ) {
			get_force_source ( N, s, dens_prev, u_prev, v_prev );
			vel_step ( N, u, v, u_prev, v_prev, visc, dt );
			dens_step ( N, dens, dens_prev, u, v, diff, dt );
		}
		clock_gettime(CLOCK_MONOTONIC, &t0);
		for ( s=5 ; s<5+steps ; s++ ) {
			get_force_source ( N, s, dens_prev, u_prev, v_prev );
			vel_step ( N, u, v, u_prev, v_prev, visc, dt );
			dens_step ( N, dens, dens_prev, u, v, diff, dt );
		}
		clock_gettime(CLOCK_MONOTONIC, &t1);
		printf("{\"n\":%d,\"steps\":%d,\"per_step_s\":%.9g,\"checksum\":%.9g}\n", N, steps,
			((t1.tv_sec-t0.tv_sec) + 1e-9*(t1.tv_nsec-t0.tv_nsec)) / (steps > 0 ? steps : 1), dens[IX(N/2,N/2)]);
	}
	return 0;
}
