C     A UMAT that does nothing: it returns at once, leaving STRESS,
C     STATEV and every other argument as the adapter passed them.
C     For benchmarks/run --materials only: the time of a run with it,
C     against linear_elastic, is the floor of the per-point UMAT
C     interface (the adapter's preparation and checks and the call with
C     the Abaqus argument list), with no constitutive work at all.
      SUBROUTINE UMAT(STRESS,STATEV,DDSDDE,SSE,SPD,SCD,
     1 RPL,DDSDDT,DRPLDE,DRPLDT,
     2 STRAN,DSTRAN,TIME,DTIME,TEMP,DTEMP,PREDEF,DPRED,CMNAME,
     3 NDI,NSHR,NTENS,NSTATV,PROPS,NPROPS,COORDS,DROT,PNEWDT,
     4 CELENT,DFGRD0,DFGRD1,NOEL,NPT,LAYER,KSPT,KSTEP,KINC)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      CHARACTER*80 CMNAME
      DIMENSION STRESS(NTENS),STATEV(NSTATV)
      RETURN
      END
