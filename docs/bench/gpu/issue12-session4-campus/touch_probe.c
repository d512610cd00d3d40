#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include <pthread.h>
static double now(){struct timespec t;clock_gettime(CLOCK_MONOTONIC,&t);return t.tv_sec+t.tv_nsec*1e-9;}
static size_t per; static char* base;
static void* work(void* a){ size_t i=(size_t)a; char* p=base+i*per; for(size_t o=0;o<per;o+=4096) p[o]=1; return 0;}
int main(int argc,char**argv){ size_t mb=atol(argv[1]); int th=atoi(argv[2]); int huge=atoi(argv[3]);
 size_t n=mb<<20; base=mmap(0,n+(2<<20),PROT_READ|PROT_WRITE,MAP_PRIVATE|MAP_ANONYMOUS,-1,0);
 base=(char*)(((size_t)base+(2<<20)-1)&~((size_t)(2<<20)-1));
 if(huge) madvise(base,n,MADV_HUGEPAGE); per=n/th; pthread_t t[64]; double t0=now();
 for(int i=0;i<th;i++) pthread_create(&t[i],0,work,(void*)(size_t)i); for(int i=0;i<th;i++) pthread_join(t[i],0);
 double d=now()-t0; printf("first touch %zu MiB, %d threads, huge %d: %.1f ms (%.2f GB/s)\n",mb,th,huge,d*1e3,n/d/1e9);
 t0=now(); for(int i=0;i<th;i++) pthread_create(&t[i],0,work,(void*)(size_t)i); for(int i=0;i<th;i++) pthread_join(t[i],0);
 d=now()-t0; printf("second touch: %.1f ms\n",d*1e3); return 0;}
