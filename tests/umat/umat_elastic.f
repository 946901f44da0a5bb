C     Isotropic linear elasticity in the Abaqus UMAT form, for the empm
C     UMAT adapter tests (tests/umat). PROPS(1) = E, PROPS(2) = NU.
C     The stress increment is written with the same operations, in the
C     same order, as empm's native linear_elastic model, so that the two
C     agree to round-off: lambda tr(de) + 2 mu de on the direct
C     components, mu gamma on the (engineering) shears.
C     State: STATEV(1) counts the increments, STATEV(2) is the time at
C     the end of the last one (TIME(2) + DTIME): NSTATV must be 2.
C     SSE accumulates the trapezoidal work of the increments.
C     PROPS(4) (optional) = 1: neither DDSDDE nor SSE (an explicit code
C     uses neither; the native model computes neither: for measuring
C     the adapter's overhead with a UMAT doing the native model's work).
      SUBROUTINE UMAT(STRESS,STATEV,DDSDDE,SSE,SPD,SCD,
     1 RPL,DDSDDT,DRPLDE,DRPLDT,
     2 STRAN,DSTRAN,TIME,DTIME,TEMP,DTEMP,PREDEF,DPRED,CMNAME,
     3 NDI,NSHR,NTENS,NSTATV,PROPS,NPROPS,COORDS,DROT,PNEWDT,
     4 CELENT,DFGRD0,DFGRD1,NOEL,NPT,LAYER,KSPT,KSTEP,KINC)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      CHARACTER*80 CMNAME
      DIMENSION STRESS(NTENS),STATEV(NSTATV),
     1 DDSDDE(NTENS,NTENS),DDSDDT(NTENS),DRPLDE(NTENS),
     2 STRAN(NTENS),DSTRAN(NTENS),TIME(2),PREDEF(1),DPRED(1),
     3 PROPS(NPROPS),COORDS(3),DROT(3,3),DFGRD0(3,3),DFGRD1(3,3)
      DIMENSION SOLD(6)
C
      E = PROPS(1)
      ANU = PROPS(2)
      ALAMB = E*ANU/((1.D0+ANU)*(1.D0-2.D0*ANU))
      AMU = E/(2.D0*(1.D0+ANU))
      TWOMU = 2.D0*AMU
      IF (NPROPS .GE. 4) THEN
        IF (NINT(PROPS(4)) .EQ. 1) GO TO 55
      END IF
C     Jacobian
      DO 20 J = 1, NTENS
        DO 10 I = 1, NTENS
          DDSDDE(I,J) = 0.D0
   10   CONTINUE
   20 CONTINUE
      DO 40 J = 1, NDI
        DO 30 I = 1, NDI
          DDSDDE(I,J) = ALAMB
   30   CONTINUE
        DDSDDE(J,J) = ALAMB + TWOMU
   40 CONTINUE
      DO 50 I = NDI+1, NTENS
        DDSDDE(I,I) = AMU
   50 CONTINUE
C     Stress update, SSE
      DO 60 I = 1, NTENS
        SOLD(I) = STRESS(I)
   60 CONTINUE
      CALL UELSTR(STRESS, DSTRAN, NDI, NTENS, ALAMB, TWOMU, AMU)
      DO 90 I = 1, NTENS
        SSE = SSE + 0.5D0*(SOLD(I) + STRESS(I))*DSTRAN(I)
   90 CONTINUE
      GO TO 95
C     Stress update only
   55 CALL UELSTR(STRESS, DSTRAN, NDI, NTENS, ALAMB, TWOMU, AMU)
   95 CONTINUE
C     State: this UMAT assumes NSTATV = 2
      STATEV(1) = STATEV(1) + 1.D0
      STATEV(2) = TIME(2) + DTIME
      RETURN
      END
C
C     The elastic stress increment, in linear_elastic's operation order.
      SUBROUTINE UELSTR(STRESS, DSTRAN, NDI, NTENS, ALAMB, TWOMU, AMU)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      DIMENSION STRESS(NTENS), DSTRAN(NTENS)
      TR = DSTRAN(1) + DSTRAN(2) + DSTRAN(3)
      DO 10 I = 1, NDI
        STRESS(I) = STRESS(I) + ALAMB*TR + TWOMU*DSTRAN(I)
   10 CONTINUE
      DO 20 I = NDI+1, NTENS
        STRESS(I) = STRESS(I) + AMU*DSTRAN(I)
   20 CONTINUE
      RETURN
      END
